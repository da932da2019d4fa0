//! Device options shared by `tendril run --hardware real` and `tendril latency`.

use crate::cell::real::RealCellConfig;
use crate::run::scenario::PickPlaceScenario;

/// Where the real (or virtual) devices are.
#[derive(Debug, Clone, clap::Args)]
pub struct DeviceArgs {
    /// UR controller host (RTDE on 30004, URScript on 30002).
    #[arg(long, default_value = "127.0.0.1")]
    ur: String,
    /// Dynamixel serial port (a USB adapter, or the pty `tendril serve` prints).
    #[arg(long)]
    dxl: Option<String>,
    /// Dynamixel bus baud rate [bit/s].
    #[arg(long, default_value_t = 57_600)]
    dxl_baud: u32,
    /// HYPERION interrogator host (51971 commands, 51972 peaks).
    #[arg(long, default_value = "127.0.0.1")]
    interrogator: String,
    /// Non-standard ports, as `tendril serve --port-base N` uses: RTDE N, URScript N+1,
    /// HYPERION commands N+2, peaks N+3.
    #[arg(long)]
    port_base: Option<u16>,
    /// Sensor watchdog: stop when the latest peak sample is this many interrogator periods old.
    #[arg(long, default_value_t = 5.0)]
    sensor_stale_samples: f64,
}

impl DeviceArgs {
    /// The cell configuration; the interrogator period comes from the scenario.
    pub fn config(&self, scenario: &PickPlaceScenario) -> anyhow::Result<RealCellConfig> {
        let dxl = self.dxl.as_deref().ok_or_else(|| anyhow::anyhow!("--hardware real needs --dxl PORT"))?;
        anyhow::ensure!(
            self.sensor_stale_samples.is_finite() && self.sensor_stale_samples >= 1.0,
            "--sensor-stale-samples must be at least 1"
        );
        let mut c = RealCellConfig::new(&self.ur, dxl, &self.interrogator);
        c.dxl_baud = self.dxl_baud;
        c.sensor_period_s = 1.0 / scenario.interrogator.sample_rate_hz;
        c.sensor_stale_samples = self.sensor_stale_samples;
        if let Some(base) = self.port_base {
            c.rtde_port = base;
            c.script_port = base + 1;
            c.command_port = base + 2;
            c.stream_port = base + 3;
        }
        Ok(c)
    }
}
