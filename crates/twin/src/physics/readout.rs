//! What a run of the physics hands out, whichever engine steps it: the readout after each step
//! ([`PhysicsReadout`]) and the state recorded for `tendril render` ([`Snapshot`]).

use tendril_fbg::array::PerPad;

/// One state of the scene in MuJoCo's layout (the compiled [`super::SceneModel`]'s `qpos`,
/// `qvel`, `ctrl`, `act`).
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Generalised positions.
    pub qpos: Vec<f64>,
    /// Generalised velocities.
    pub qvel: Vec<f64>,
    /// Actuator controls.
    pub ctrl: Vec<f64>,
    /// Actuator activations.
    pub act: Vec<f64>,
}

/// What the physics reports after a step (SI units, world frame).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PhysicsReadout {
    /// Simulated time \[s\].
    pub time_s: f64,
    /// Normal force of the object on the sensor pad (casing and bump) \[N\]: the FBG sensor's input.
    pub pad_force_n: f64,
    /// Normal force of the object on each further pad of a sensor array \[N\] (empty without one).
    pub extra_pad_forces_n: PerPad<f64>,
    /// Sum of the normal forces between the object and the whole finger, pad included \[N\].
    pub grip_force_n: f64,
    /// Normal force between the object and the palm beside the guide exit \[N\] (not part of the grip
    /// force: the palm is the hand, not the finger).
    pub palm_force_n: f64,
    /// Number of active object-finger contacts.
    pub grip_contacts: usize,
    /// Whether the object touches the finger at all.
    pub touching: bool,
    /// Object body origin (footprint centre) \[m\].
    pub object_pos_m: [f64; 3],
    /// Object orientation (w, x, y, z).
    pub object_quat: [f64; 4],
    /// Linear velocity of the object's grip centre (the middle of the wrapped handle or neck) [m/s].
    pub object_vel_m_s: [f64; 3],
    /// The object's grip centre expressed in the hand frame \[m\]: its change is the slip distance (hand z
    /// points down in the pick pose, so a falling object's z grows).
    pub object_in_hand_m: [f64; 3],
    /// Speed of the object's grip centre relative to the hand point it coincides with [m/s].
    pub slip_speed_m_s: f64,
    /// Hand (flange) position \[m\].
    pub hand_pos_m: [f64; 3],
    /// Finger growth out of the guide \[m\] (actual motor position).
    pub growth_m: f64,
    /// Tendon wound in by the twine motor \[m\] (actual motor position).
    pub twine_m: f64,
    /// The twine servo's current setpoint \[m\] (the command after the motor speed limit).
    pub twine_setpoint_m: f64,
    /// Creep elongation of the Maxwell branch \[m\].
    pub creep_m: f64,
    /// Tendon tension, both branches \[N\].
    pub tendon_tension_n: f64,
    /// Arm joint angles \[rad\] (kinematic mode: the rate-limited commanded angles).
    pub arm_q: [f64; 6],
    /// The object's vertical load on the arm \[N\]: the upward (world +z) component of every
    /// contact force the arm and what it carries (links, hand, palm, strip, pad) exert on the
    /// object, so an object hanging still in the grip reads its weight. What the arm's wrist force
    /// sensor adds to the tool's own load ([`crate::wrist`]). MuJoCo sums its contact forces;
    /// rapier, whose friction impulses stay inside its solver, takes it from the object's momentum
    /// over the step. `None` where a backend cannot tell it.
    pub tool_load_n: Option<f64>,
    /// A produce item's damage and stem (`None` for a rigid object).
    pub produce: Option<super::produce_run::ProduceReadout>,
}
