//! The [`Cell`] trait and what crosses it each tick.

use crate::Phase;
use serde::{Deserialize, Serialize};
use tendril_fbg::array::{ArrayPeaks, PerPad};
use tendril_fbg::signals::Wavelengths;

/// Standard gravity \[m/s²\] (ISO 80000-3), for the weights the control side reasons about.
pub const G_M_S2: f64 = 9.80665;

/// Number of UR5e joints.
pub const ARM_JOINTS: usize = 6;

/// How many control ticks in a row the loop may run without a fresh, valid sensor sample, holding
/// the last estimate: 10, 0.1 s at the default 100 Hz, a twentieth of the closed loop's time
/// constant (≈ 2 s). Holding the estimate that long cannot move the grip far (at the PID's 90 °/s
/// limit the twine turns 9°, ≈ 0.2 N on the finger's force gain), while a sensor that stays bad
/// or silent longer leaves the loop blind and must stop the run. The runner counts invalid samples
/// against it; a real cell's watchdog counts the ticks a device stream misses
/// (`tendril_drivers::Watchdog`).
pub const BLIND_TICKS: u32 = 10;

/// The lifecycle states of a cell (ros2_control's managed-node states, minus error handling).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Lifecycle {
    /// Created; devices not yet contacted / scene not yet built.
    Unconfigured,
    /// Devices reached and checked, outputs disabled (motors unpowered, arm not following).
    Inactive,
    /// Commands are executed.
    Active,
}

/// What the cell reports at each tick. All angles in radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CellState {
    /// Cell time in seconds since activation (simulated or wall clock).
    pub time_s: f64,
    /// Measured arm joint positions \[rad\].
    pub arm_q: [f64; ARM_JOINTS],
    /// Measured growth motor position \[rad\] (the MX-106 feeding the strip out).
    pub growth_motor_rad: f64,
    /// Measured twine motor position \[rad\] (the MX-106 pulling the curl tendon).
    pub twine_motor_rad: f64,
    /// The latest interrogator sample (of pad 0, the paper's pad).
    pub wavelengths: Wavelengths,
    /// The further pads' samples of a sensor array, taken with pad 0's (empty without one).
    pub array: ArrayPeaks,
    /// The vertical load the tool carries \[N\], positive downward: what the arm's wrist force
    /// sensor reads of the held object (and anything else pressing on the tool), its own payload
    /// compensated. A UR5e reports it as minus the z component of RTDE `actual_TCP_force` (the
    /// external force on the tool, base frame). `None` when the cell does not measure it.
    pub tool_load_n: Option<f64>,
}

/// What the control code asks of the cell at each tick. Position targets, radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CellCommand {
    /// Arm joint position targets \[rad\]; the caller keeps them within speed and acceleration limits.
    pub arm_q: [f64; ARM_JOINTS],
    /// Growth motor position target \[rad\].
    pub growth_motor_rad: f64,
    /// Twine motor position target \[rad\].
    pub twine_motor_rad: f64,
}

/// Quantities only a simulation knows; logged in traces when the cell offers them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct GroundTruth {
    /// True normal force on the sensor bump \[N\].
    pub sensor_force_n: f64,
    /// True normal force on each further pad of a sensor array \[N\] (empty without one).
    pub array_force_n: PerPad<f64>,
    /// Total normal force between finger and object \[N\].
    pub grip_force_n: f64,
    /// Height of the object's footprint centre (its body origin) above the table top \[m\]: 0 while it
    /// stands on the table, the lift once it is carried.
    pub object_height_m: f64,
    /// Speed of the object relative to the hand [m/s].
    pub slip_speed_m_s: f64,
    /// Whether the finger (or pad) touches the object at all.
    pub in_contact: bool,
    /// Where the object's grip point sits in the hand's frame \[m\]; its change is slip.
    pub object_in_hand_m: [f64; 3],
    /// A produce item's damage and stem (`None` for a rigid object).
    pub produce: Option<ProduceTruth>,
}

/// A produce item's contact pressure and stem, as only a simulation knows them. The run's figures
/// accumulate over every physics step, the last step's are what a trace samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct ProduceTruth {
    /// The last step's largest peak contact pressure on the item \[Pa\].
    pub pressure_pa: f64,
    /// The last step's area above the bruise threshold \[m²\].
    pub area_above_m2: f64,
    /// The run's largest peak contact pressure \[Pa\].
    pub peak_pa: f64,
    /// What pressed there (`pad_bump`, `pad_casing`, `strip`, `palm`, `other`; empty: nothing).
    pub peak_at: &'static str,
    /// The run's largest area above the bruise threshold at one step \[m²\].
    pub max_area_above_m2: f64,
    /// Time with some contact above the bruise threshold \[s\].
    pub time_above_s: f64,
    /// The item's bruise threshold \[Pa\].
    pub bruise_pa: f64,
    /// Whether the item started on its plant (a harvest).
    pub harvest: bool,
    /// The stem's tension at the last step \[N\] (0 without a stem, or once it let go).
    pub stem_tension_n: f64,
    /// The stem's largest tension \[N\].
    pub max_stem_tension_n: f64,
    /// The force at which the stem lets go \[N\] (`None`: the item has none).
    pub detach_n: Option<f64>,
    /// Cell time the stem let go \[s\] (`None`: still attached, or no stem).
    pub detached_s: Option<f64>,
    /// Normal force on the sensor pad's bump alone \[N\] (the sensor's input is the bump's and
    /// the casing's together).
    pub pad_bump_force_n: f64,
}

/// Percentiles of a timing over a run \[ms\].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Spread {
    /// Median \[ms\].
    pub p50_ms: f64,
    /// 99th percentile \[ms\].
    pub p99_ms: f64,
    /// Largest \[ms\].
    pub max_ms: f64,
}

impl Spread {
    /// The spread of `values_s` \[s\] (all zero when empty).
    pub fn of(values_s: &[f64]) -> Spread {
        if values_s.is_empty() {
            return Spread::default();
        }
        let mut v = values_s.to_vec();
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize] * 1e3;
        Spread { p50_ms: at(0.5), p99_ms: at(0.99), max_ms: at(1.0) }
    }
}

/// How a real cell's device streams kept up over a run: how old each stream's latest sample was
/// when a tick read it, against the watchdog's limit, and how late the ticks were. What a user
/// reads to see how close a run on an ordinary PC came to a watchdog stop.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct DeviceTiming {
    /// Age of the interrogator's latest peak sample at each tick.
    pub sensor_age: Spread,
    /// Age of the arm's latest RTDE sample at each tick.
    pub arm_age: Spread,
    /// Age of the motors' latest positions at each tick.
    pub motor_age: Spread,
    /// How late each tick's read came after its deadline.
    pub tick_late: Spread,
    /// The watchdog's limits: sensor, arm, motors \[ms\].
    pub watchdog_ms: [f64; 3],
}

/// Why a cell operation failed.
#[derive(Debug, thiserror::Error)]
pub enum CellError {
    /// A lifecycle method was called in the wrong state.
    #[error("cannot {action} a cell that is {state:?}")]
    Lifecycle {
        /// What was attempted.
        action: &'static str,
        /// The state the cell was in.
        state: Lifecycle,
    },
    /// The physics diverged or failed; `time_s` is when it was detected.
    #[error("physics failed at t = {time_s:.4} s: {cause}")]
    Physics {
        /// Simulated time of detection \[s\].
        time_s: f64,
        /// What went wrong.
        cause: String,
    },
    /// A device did not answer or answered wrongly.
    #[error("device {device}: {cause}")]
    Device {
        /// Which device.
        device: String,
        /// What went wrong.
        cause: String,
    },
    /// Set-up failed (scene could not be built, device not found...).
    #[error("configure: {0}")]
    Configure(String),
    /// An operator stop (Ctrl-C, SIGTERM, SIGHUP; see [`crate::interrupt`]) ended the run.
    #[error("stopped by {signal} at t = {time_s:.3} s")]
    Stopped {
        /// The signal's name.
        signal: &'static str,
        /// Cell time of the stop \[s\].
        time_s: f64,
    },
}

/// A gripping cell: arm, gripper motors and interrogator behind one lifecycle.
pub trait Cell {
    /// A short name for summaries (`"mujoco"`, `"real"`).
    fn backend(&self) -> &str;
    /// The current lifecycle state.
    fn lifecycle(&self) -> Lifecycle;
    /// Unconfigured → Inactive: build the scene / connect to the devices and check them.
    fn configure(&mut self) -> Result<(), CellError>;
    /// Inactive → Active: enable outputs; cell time starts at 0.
    fn activate(&mut self) -> Result<(), CellError>;
    /// Active → Inactive: stop the arm, leave the motors holding, disable outputs. Safe to call on error paths.
    fn deactivate(&mut self) -> Result<(), CellError>;
    /// Reads the latest state (Active only).
    fn read(&mut self) -> Result<CellState, CellError>;
    /// Sends position targets (Active only).
    fn write(&mut self, command: &CellCommand) -> Result<(), CellError>;
    /// Lets time pass until cell time `time_s`: a simulation steps, a real cell sleeps.
    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError>;
    /// How the device streams kept up so far, when the cell has devices (a real cell).
    fn device_timing(&self) -> Option<DeviceTiming> {
        None
    }
    /// Ground truth, when the cell is a simulation.
    fn ground_truth(&self) -> Option<GroundTruth> {
        None
    }
    /// Tells the cell that the task entered `phase` at cell time `time_s` (the runner calls it on
    /// every phase change, before the tick's write). The twin times its scenario disturbances
    /// (`[disturbance]`) from it; a real cell has none and ignores it.
    fn phase_started(&mut self, _phase: Phase, _time_s: f64) {}
    /// Whether the wavelengths of the last [`Cell::read`] are a new interrogator sample (`false`
    /// when the interrogator delivered nothing since the read before, as in the twin's
    /// `[disturbance.dropout]`, or a real cell's stream late by a tick). A stream silent for long
    /// is the real cell's watchdog's to stop.
    fn sample_is_new(&self) -> bool {
        true
    }
}

/// Checks a lifecycle transition: `Ok` when the cell is in `expected`.
pub fn require_state(current: Lifecycle, expected: Lifecycle, action: &'static str) -> Result<(), CellError> {
    if current == expected { Ok(()) } else { Err(CellError::Lifecycle { action, state: current }) }
}

/// A cell borrowed is a cell: a run can step a cell its caller keeps (and reads afterwards).
impl<C: Cell + ?Sized> Cell for &mut C {
    fn backend(&self) -> &str {
        (**self).backend()
    }
    fn lifecycle(&self) -> Lifecycle {
        (**self).lifecycle()
    }
    fn configure(&mut self) -> Result<(), CellError> {
        (**self).configure()
    }
    fn activate(&mut self) -> Result<(), CellError> {
        (**self).activate()
    }
    fn deactivate(&mut self) -> Result<(), CellError> {
        (**self).deactivate()
    }
    fn read(&mut self) -> Result<CellState, CellError> {
        (**self).read()
    }
    fn write(&mut self, command: &CellCommand) -> Result<(), CellError> {
        (**self).write(command)
    }
    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError> {
        (**self).wait_until(time_s)
    }
    fn device_timing(&self) -> Option<DeviceTiming> {
        (**self).device_timing()
    }
    fn ground_truth(&self) -> Option<GroundTruth> {
        (**self).ground_truth()
    }
    fn phase_started(&mut self, phase: Phase, time_s: f64) {
        (**self).phase_started(phase, time_s);
    }
    fn sample_is_new(&self) -> bool {
        (**self).sample_is_new()
    }
}
