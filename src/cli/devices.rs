//! Device options of `tendril run --hardware real`.

use crate::cell::real::RealCellConfig;
use crate::cell::real::realtime::RealtimeOptions;
use crate::run::scenario::PickPlaceScenario;
use crate::scenario::Override;

/// Where the real (or virtual) devices are, how strict the watchdog is, how the control thread
/// is scheduled. Motor IDs, bus speed and FBG windows are the scenario's `[hardware]`.
#[derive(Debug, Clone, clap::Args)]
pub struct DeviceArgs {
    /// UR controller host (RTDE on 30004, URScript on 30002).
    #[arg(long, default_value = "127.0.0.1")]
    ur: String,
    /// Dynamixel serial port (a USB adapter, or the pty `tendril serve` prints).
    #[arg(long)]
    dxl: Option<String>,
    /// Dynamixel bus speed [bit/s]; short for `--set hardware.dxl_baud=N` (default: the scenario's).
    #[arg(long)]
    dxl_baud: Option<u32>,
    /// HYPERION interrogator host (51971 commands, 51972 peaks).
    #[arg(long, default_value = "127.0.0.1")]
    interrogator: String,
    /// Non-standard ports, as `tendril serve --port-base N` uses: RTDE N, URScript N+1,
    /// HYPERION commands N+2, peaks N+3, UR dashboard N+4.
    #[arg(long, value_parser = port_base)]
    port_base: Option<u16>,
    /// Sensor watchdog: stop when the latest peak sample is this many interrogator periods old.
    #[arg(long, default_value_t = 5.0)]
    sensor_stale_samples: f64,
    /// Arm watchdog: stop when the latest RTDE sample is this old [ms] (5 periods at 500 Hz).
    #[arg(long, default_value_t = 10.0)]
    arm_stale_ms: f64,
    /// Motor watchdog: stop when a motor has not answered within this time [ms].
    #[arg(long, default_value_t = 50.0)]
    dxl_timeout_ms: f64,
    #[command(flatten)]
    realtime: super::realtime::RealtimeArgs,
}

impl DeviceArgs {
    /// Scenario overrides these options stand for (checked like the file).
    pub fn overrides(&self) -> Vec<Override> {
        self.dxl_baud
            .map(|b| Override { key: "hardware.dxl_baud".into(), value: toml::Value::Integer(b.into()) })
            .into_iter()
            .collect()
    }

    /// The control thread's scheduling.
    pub fn realtime(&self) -> anyhow::Result<RealtimeOptions> {
        self.realtime.options()
    }

    /// The cell configuration; the interrogator period and `[hardware]` come from the scenario.
    pub fn config(&self, scenario: &PickPlaceScenario) -> anyhow::Result<RealCellConfig> {
        let dxl = self.dxl.as_deref().ok_or_else(|| anyhow::anyhow!("--hardware real needs --dxl PORT"))?;
        anyhow::ensure!(
            self.sensor_stale_samples.is_finite() && self.sensor_stale_samples >= 1.0,
            "--sensor-stale-samples must be at least 1"
        );
        anyhow::ensure!(
            self.arm_stale_ms.is_finite() && self.arm_stale_ms >= 2.0,
            "--arm-stale-ms must be at least 2 (one RTDE period)"
        );
        anyhow::ensure!(
            self.dxl_timeout_ms.is_finite() && (1.0..=10_000.0).contains(&self.dxl_timeout_ms),
            "--dxl-timeout-ms must be 1-10000"
        );
        let mut c = RealCellConfig::new(&self.ur, dxl, &self.interrogator);
        c.dxl_reply_timeout = std::time::Duration::from_secs_f64(self.dxl_timeout_ms * 1e-3);
        c.hardware = scenario.hardware;
        c.sensor_period_s = 1.0 / scenario.interrogator.sample_rate_hz;
        c.sensor_stale_samples = self.sensor_stale_samples;
        c.arm_stale_s = self.arm_stale_ms * 1e-3;
        Ok(match self.port_base {
            Some(base) => c.with_port_base(base),
            None => c,
        })
    }
}

/// Parses `--port-base N`: six ports N..N+5 must fit below 65536.
pub fn port_base(text: &str) -> Result<u16, String> {
    let base: u16 = text.parse().map_err(|e| format!("{e}"))?;
    if base == 0 || base > u16::MAX - 5 {
        return Err(format!("must be 1-{} (ports N..N+5)", u16::MAX - 5));
    }
    Ok(base)
}
