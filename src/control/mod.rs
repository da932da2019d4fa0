//! Control code shared by the simulated and the real cell: it talks to the cell only through
//! [`crate::hardware::Cell`].
//!
//! - [`estimate`]: the force estimate of eq. (8) with temperature compensation.
//! - [`hysteresis`]: Prandtl-Ishlinskii operators (forward model and its inverse).
//! - [`gripper`]: motor angles to finger growth and tendon pull.
//! - [`task`]: the pick-and-place sequence.
//! - [`contact`]: first contact of the guarded close, robust to the sensor's noise.
//! - [`controller`]: the force-controller seam ([`controller::ForceController`]) and `[controller]`.
//! - [`pid`]: the paper's force controller, a PID (output: twine motor speed).
//! - [`feedforward`]: the PID on a setpoint scheduled from the arm's planned motion.
//! - [`slip_margin`]: a grip kept a margin above the friction limit of the planned load.
//! - [`trajectory`]: joint-space moves within the paper's speed and acceleration limits.
//! - [`slip`]: slip and drop detection from the force estimate and the wrist's load.
//! - [`load`]: the wrist's cues (the carried load falling; the object's weight missing).

pub mod contact;
pub mod controller;
pub mod estimate;
pub mod feedforward;
pub mod gripper;
pub mod hysteresis;
pub mod load;
pub mod pid;
pub mod slip;
pub mod slip_margin;
pub mod task;
pub mod trajectory;

/// Standard gravity \[m/s²\] (ISO 80000-3), for the weights the control side reasons about.
pub const G_M_S2: f64 = 9.80665;
