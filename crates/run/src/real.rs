//! One scenario on the real cell (or the virtual devices): the same control loop as the twin,
//! behind [`LimitedCell`] over [`RealCell`]; writes the same `trace.csv` and `summary.json`
//! (`backend: "real"`).

use super::execute::{Driver, run_on_cell_with};
use super::runner::RunReport;
use super::scenario::PickPlaceScenario;
use super::summary::RunSummary;
use std::path::Path;
use tendril_control::limits::{LimitedCell, SafetyLimits};
use tendril_drivers::{HardwareConfig, RealCell, RealCellConfig};

/// Where the devices are and how strict the watchdogs are: what `tendril run --hardware real`
/// takes on its command line (and `tendril.run(..., hardware="real")` as arguments). Motor IDs,
/// bus speed and FBG windows are the scenario's `[hardware]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Devices {
    /// UR controller host (RTDE on 30004, URScript on 30002).
    pub ur: String,
    /// Dynamixel serial port (a USB adapter, or the pty `tendril serve` prints).
    pub dxl: String,
    /// HYPERION interrogator host (51971 commands, 51972 peaks).
    pub interrogator: String,
    /// Non-standard ports, as `tendril serve --port-base N` uses: RTDE N, URScript N+1,
    /// HYPERION commands N+2, peaks N+3, UR dashboard N+4.
    pub port_base: Option<u16>,
    /// Sensor watchdog \[ms\] (`None`: the default, docs/cell/timing.md#watchdogs).
    pub sensor_stale_ms: Option<f64>,
    /// Arm watchdog \[ms\] (`None`: the default).
    pub arm_stale_ms: Option<f64>,
    /// Motor watchdog \[ms\] (`None`: the default).
    pub motor_stale_ms: Option<f64>,
}

impl Devices {
    /// The devices at their standard ports on `ur` and `interrogator`, the bus on `dxl`, the
    /// default watchdogs.
    pub fn new(ur: &str, dxl: &str, interrogator: &str) -> Devices {
        Devices {
            ur: ur.into(),
            dxl: dxl.into(),
            interrogator: interrogator.into(),
            port_base: None,
            sensor_stale_ms: None,
            arm_stale_ms: None,
            motor_stale_ms: None,
        }
    }

    /// The cell configuration for `scenario`: the interrogator period and `[hardware]` come from
    /// it ([`hardware_for`]: with a sensor array, every pad's windows), the watchdogs from its
    /// control rate unless given. A limit below one period of its stream or above 10 s, or a port
    /// base whose six ports do not fit, is refused with the reason.
    pub fn config(&self, scenario: &PickPlaceScenario) -> anyhow::Result<RealCellConfig> {
        let mut c = RealCellConfig::new(&self.ur, &self.dxl, &self.interrogator);
        c.hardware = hardware_for(scenario)?;
        c.sensor_period_s = 1.0 / scenario.interrogator.sample_rate_hz;
        let mut c = c.with_control_rate(scenario.control_rate_hz);
        // The limits: at least one period of their stream, at most 10 s (a UR5e's own program
        // watchdog stops the arm after 0.5 s without our inputs).
        let w = &mut c.watchdog;
        for (flag, given, limit, least_ms) in [
            ("sensor_stale_ms", self.sensor_stale_ms, &mut w.sensor_stale_s, c.sensor_period_s * 1e3),
            ("arm_stale_ms", self.arm_stale_ms, &mut w.arm_stale_s, 1e3 / tendril_drivers::ur::OUTPUT_RATE_HZ),
            ("motor_stale_ms", self.motor_stale_ms, &mut w.motor_stale_s, 1.0),
        ] {
            if let Some(ms) = given {
                anyhow::ensure!(
                    ms.is_finite() && (least_ms..=10_000.0).contains(&ms),
                    "{flag} must be {least_ms}-10000 (one period of its stream to 10 s), got {ms}"
                );
                *limit = ms * 1e-3;
            }
        }
        Ok(match self.port_base {
            Some(base) => c.with_port_base(check_port_base(base)?),
            None => c,
        })
    }
}

/// The scenario's `[hardware]` with every pad's windows: with a sensor array, the further pads'
/// `[[hardware.fbg.pads]]` as given, or derived from the `[array]` layout
/// (`FbgWindows::for_layout` of `tendril_hyperion`); the single pad's unchanged. A layout the windows
/// cannot read is refused with the key and the reason (as validation does).
pub fn hardware_for(scenario: &PickPlaceScenario) -> anyhow::Result<HardwareConfig> {
    let mut h = scenario.hardware;
    h.fbg = h.fbg.for_layout(&scenario.array, &scenario.sensor).map_err(|faults| {
        let lines: Vec<String> = faults.iter().map(|(key, reason)| format!("{key}: {reason}")).collect();
        anyhow::anyhow!("scenario {}: {}", scenario.name, lines.join("; "))
    })?;
    Ok(h)
}

/// A port base whose six ports N..N+5 fit below 65536.
pub fn check_port_base(base: u16) -> anyhow::Result<u16> {
    anyhow::ensure!(base != 0 && base <= u16::MAX - 5, "port base {base}: must be 1-{} (ports N..N+5)", u16::MAX - 5);
    Ok(base)
}

/// Runs `scenario` on the real cell. A device fault during the run is an `error` outcome (after a
/// clean stop); `Err` is for what prevents the run from starting (output folder not writable).
pub fn run_on_real(
    scenario: &PickPlaceScenario,
    config: RealCellConfig,
    out: Option<&Path>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    run_on_real_with(scenario, config, out, Driver::default())
}

/// As [`run_on_real`], driven by `driver` (another force controller, a check between ticks).
pub fn run_on_real_with(
    scenario: &PickPlaceScenario,
    config: RealCellConfig,
    out: Option<&Path>,
    driver: Driver<'_>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    // Disturbances are the twin's: refuse before any device is contacted.
    scenario.disturbance.refuse_on_real().map_err(|e| anyhow::anyhow!("{e}"))?;
    // A configuration made by hand for a sensor array's scenario must read every pad, or the run
    // would control on pad 0 alone without a word.
    let (windows, pads) = (config.hardware.fbg.pads.len(), scenario.array.pads.len());
    anyhow::ensure!(
        windows == pads,
        "the real cell's configuration has windows for {windows} further pad(s), the scenario's [array] has {pads}: \
         make it with Devices::config or hardware_for"
    );
    let started = super::clock::RunClock::start();
    let limits = SafetyLimits::for_task(&scenario.task.limits, &scenario.estimator, &scenario.gripper);
    let mut cell = LimitedCell::new(RealCell::new(config), limits);
    run_on_cell_with(&mut cell, scenario, out, started, driver)
}
