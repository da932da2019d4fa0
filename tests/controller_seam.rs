//! The force-controller seam and the skipping of invalid sensor samples, through the library's
//! control loop (`run::runner`) on a toy cell: a perfect twine motor whose tendon presses the pad
//! with 0.02 N per degree past first contact at 60°, and an interrogator that reports the paper's
//! calibration curve for that force (plus whatever bad samples a test injects).

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use tendril_cell::gripper::GripperConfig;
use tendril_cell::{ARM_JOINTS, Cell, CellCommand, CellError, CellState, Lifecycle};
use tendril_control::ControllerConfig;
use tendril_control::controller::{ControlContext, ForceController};
use tendril_control::slip::SlipConfig;
use tendril_control::task::{Phase, TaskConfig};
use tendril_fbg::estimate::ForceCalibration;
use tendril_fbg::signals::Wavelengths;
use tendril_run::runner::{
    ControlPlan, MAX_CONSECUTIVE_INVALID_SAMPLES, Outcome, RunReport, run_task, run_task_with_controller,
};

const RATE_HZ: f64 = 100.0;

/// The toy cell; `bad` maps a tick to the sample the interrogator reports instead of the true one.
struct ToyCell {
    lifecycle: Lifecycle,
    time_s: f64,
    arm_q: [f64; ARM_JOINTS],
    growth_rad: f64,
    twine_rad: f64,
    cal: ForceCalibration,
    bad: BTreeMap<u64, Wavelengths>,
}

impl ToyCell {
    fn new(bad: BTreeMap<u64, Wavelengths>) -> ToyCell {
        ToyCell {
            lifecycle: Lifecycle::Unconfigured,
            time_s: 0.0,
            arm_q: [0.0; ARM_JOINTS],
            growth_rad: 0.0,
            twine_rad: 0.0,
            cal: ForceCalibration::default(),
            bad,
        }
    }

    fn force_n(&self) -> f64 {
        (0.02 * (self.twine_rad.to_degrees() - 60.0)).max(0.0)
    }
}

impl Cell for ToyCell {
    fn backend(&self) -> &str {
        "toy"
    }
    fn lifecycle(&self) -> Lifecycle {
        self.lifecycle
    }
    fn configure(&mut self) -> Result<(), CellError> {
        self.lifecycle = Lifecycle::Inactive;
        Ok(())
    }
    fn activate(&mut self) -> Result<(), CellError> {
        self.lifecycle = Lifecycle::Active;
        Ok(())
    }
    fn deactivate(&mut self) -> Result<(), CellError> {
        self.lifecycle = Lifecycle::Inactive;
        Ok(())
    }
    fn read(&mut self) -> Result<CellState, CellError> {
        let tick = (self.time_s * RATE_HZ).round() as u64;
        let f = self.force_n();
        let shift_pm = self.cal.a_pm_per_n2 * f * f + self.cal.b_pm_per_n * f;
        let good = Wavelengths { fbg1_nm: 1540.0 + shift_pm / 1000.0, fbg2_nm: 1550.0 };
        Ok(CellState {
            time_s: self.time_s,
            arm_q: self.arm_q,
            growth_motor_rad: self.growth_rad,
            twine_motor_rad: self.twine_rad,
            wavelengths: self.bad.get(&tick).copied().unwrap_or(good),
            array: Default::default(),
            tool_load_n: None,
        })
    }
    fn write(&mut self, command: &CellCommand) -> Result<(), CellError> {
        self.arm_q = command.arm_q;
        self.growth_rad = command.growth_motor_rad;
        self.twine_rad = command.twine_motor_rad;
        Ok(())
    }
    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError> {
        self.time_s = time_s;
        Ok(())
    }
}

fn plan(feedback: bool) -> ControlPlan {
    let task = TaskConfig { grasp_s: 4.0, lift_s: 2.0, transfer_s: 1.0, lower_s: 1.0, ..TaskConfig::default() };
    ControlPlan {
        setpoint_n: 1.0,
        feedback,
        rate_hz: RATE_HZ,
        controller: ControllerConfig::default(),
        calibration: ForceCalibration::default(),
        task,
        gripper: GripperConfig::default(),
        slip: SlipConfig::default(),
        object_weight_n: None,
        array: Default::default(),
    }
}

/// What the test controller saw.
#[derive(Debug, Default)]
struct Seen {
    resets: usize,
    phases: Vec<Phase>,
    moving_arm_ticks: usize,
    accelerating_ticks: usize,
    blocked_ticks: usize,
}

/// Bang-bang at a fixed speed, recording every context it is handed.
#[derive(Debug)]
struct BangBang {
    speed_deg_s: f64,
    seen: Arc<Mutex<Seen>>,
}

impl ForceController for BangBang {
    fn update(&mut self, ctx: &ControlContext) -> f64 {
        let mut seen = self.seen.lock().unwrap();
        if seen.phases.last() != Some(&ctx.phase) {
            seen.phases.push(ctx.phase);
        }
        assert_eq!(ctx.dt_s, 1.0 / RATE_HZ);
        assert_eq!(ctx.setpoint_n, 1.0);
        if ctx.arm.qd_rad_s.iter().any(|v| *v != 0.0) {
            seen.moving_arm_ticks += 1;
        }
        if ctx.arm.qdd_rad_s2.iter().any(|v| *v != 0.0) {
            seen.accelerating_ticks += 1;
        }
        if ctx.phase == Phase::Grasp {
            assert!(ctx.arm.qd_rad_s.iter().chain(&ctx.arm.qdd_rad_s2).all(|v| *v == 0.0), "the arm holds still");
        }
        seen.blocked_ticks += usize::from(ctx.blocked);
        if ctx.force_n < ctx.setpoint_n { self.speed_deg_s } else { -self.speed_deg_s }
    }
    fn reset(&mut self) {
        self.seen.lock().unwrap().resets += 1;
    }
    fn max_speed_deg_s(&self) -> f64 {
        self.speed_deg_s
    }
}

fn run_bang_bang(feedback: bool) -> (RunReport, Seen) {
    let seen = Arc::new(Mutex::new(Seen::default()));
    let controller = Box::new(BangBang { speed_deg_s: 30.0, seen: seen.clone() });
    let report = run_task_with_controller(&mut ToyCell::new(BTreeMap::new()), &plan(feedback), controller);
    let seen = std::mem::take(&mut *seen.lock().unwrap());
    (report, seen)
}

#[test]
fn a_trivial_controller_drives_the_task_through_the_seam() {
    let (report, seen) = run_bang_bang(true);
    assert_eq!(report.outcome, Outcome::Held, "{:?}", report.error);
    assert_eq!(report.rows.last().unwrap().phase, Phase::Done);
    use Phase::*;
    assert_eq!(seen.phases, vec![Grasp, Lift, Transfer, Lower], "on from the grasp to the end of the moves");
    assert_eq!(seen.resets, 1, "reset once, when force control starts");
    assert!(seen.moving_arm_ticks > 100 && seen.accelerating_ticks > 50, "{seen:?}");
    assert_eq!(seen.blocked_ticks, 0);
    // Bang-bang chatters about the setpoint by one step: 30 °/s × 10 ms × 0.02 N/°.
    let grasp_end = report.rows.iter().rfind(|r| r.phase == Grasp).unwrap();
    assert!((grasp_end.force_n - 1.0).abs() < 0.02, "{}", grasp_end.force_n);
    assert!(report.rows.iter().filter(|r| r.controller_on).all(|r| r.controller_output_deg_s.abs() == 30.0));
    // The release uncurls at the controller's own top speed.
    let release: Vec<_> = report.rows.iter().filter(|r| r.phase == Release).collect();
    let step = release[0].twine_motor_rad.to_degrees() - release[1].twine_motor_rad.to_degrees();
    assert!((step - 0.3).abs() < 1e-9, "{step}");

    let (report, seen) = run_bang_bang(false);
    assert_eq!(report.outcome, Outcome::Held, "{:?}", report.error);
    assert_eq!(seen.phases, vec![Grasp], "off while the arm moves");
    assert_eq!(seen.resets, 2, "reset at the grasp and again when the arm starts to move");
    assert_eq!(seen.moving_arm_ticks, 0);
}

fn nan_sample() -> Wavelengths {
    Wavelengths { fbg1_nm: f64::NAN, fbg2_nm: 1550.0 }
}

/// 2000 pm below the tare: under the calibration curve's minimum (−571 pm), no force for it.
fn below_curve_sample() -> Wavelengths {
    Wavelengths { fbg1_nm: 1538.0, fbg2_nm: 1550.0 }
}

#[test]
fn invalid_samples_are_skipped_held_and_counted() {
    let clean = run_task(&mut ToyCell::new(BTreeMap::new()), &plan(true));
    assert_eq!(clean.outcome, Outcome::Held, "{:?}", clean.error);
    assert_eq!(clean.invalid_samples, 0);

    // Isolated bad samples at home (during the tare) and in the grasp, and a run one short of
    // the limit during the lift.
    let mut bad = BTreeMap::new();
    bad.insert(10, nan_sample());
    bad.insert(700, below_curve_sample());
    bad.insert(701, nan_sample());
    bad.insert(900, Wavelengths { fbg1_nm: 1540.0, fbg2_nm: f64::INFINITY });
    let lift_tick = (clean.motion_start_s.unwrap() * RATE_HZ).round() as u64 + 50;
    let long = u64::from(MAX_CONSECUTIVE_INVALID_SAMPLES) - 1;
    for t in lift_tick..lift_tick + long {
        bad.insert(t, below_curve_sample());
    }
    let report = run_task(&mut ToyCell::new(bad.clone()), &plan(true));
    assert_eq!(report.outcome, Outcome::Held, "{:?}", report.error);
    assert_eq!(report.error, None);
    assert_eq!(report.invalid_samples, bad.len() as u64);
    // Each bad tick holds the last valid estimate.
    for &tick in bad.keys().filter(|&&t| t > 10) {
        let (before, at) = (&report.rows[tick as usize - 1], &report.rows[tick as usize]);
        assert_eq!(at.force_n.to_bits(), before.force_n.to_bits(), "tick {tick}");
        assert!(at.force_n.is_finite());
    }
    // A NaN at home does not poison the tare: the unloaded reading is the clean run's.
    assert_eq!(report.rows[20].force_n.to_bits(), clean.rows[20].force_n.to_bits());
}

#[test]
fn a_long_run_of_invalid_samples_ends_the_run() {
    let limit = u64::from(MAX_CONSECUTIVE_INVALID_SAMPLES);
    let bad: BTreeMap<u64, Wavelengths> = (600..600 + limit).map(|t| (t, below_curve_sample())).collect();
    let report = run_task(&mut ToyCell::new(bad), &plan(true));
    assert_eq!(report.outcome, Outcome::Error);
    let error = report.error.clone().unwrap();
    assert!(error.contains(&format!("{limit} consecutive invalid samples")), "{error}");
    assert!(error.contains("invalid discriminant") && error.contains("estimator"), "{error}");
    assert_eq!(report.invalid_samples, limit);
    // The run stopped on the last bad sample: the rows before it are kept.
    assert_eq!(report.rows.len() as u64, 600 + limit - 1);
}
