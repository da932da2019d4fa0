//! Device options of `tendril run --hardware real`.

use tendril_config::Override;
use tendril_drivers::RealCellConfig;
use tendril_drivers::realtime::RealtimeOptions;
use tendril_run::real::Devices;
use tendril_run::scenario::PickPlaceScenario;

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
    /// Sensor watchdog: stop when the latest peak sample is this old [ms] [default: 10 control
    /// ticks plus one interrogator period, 101 ms at 100 Hz and 1 kHz; docs/cell/timing.md#watchdogs].
    #[arg(long)]
    sensor_stale_ms: Option<f64>,
    /// Arm watchdog: stop when the latest RTDE sample is this old [ms] [default: 10 control ticks
    /// plus one RTDE period, 102 ms at 100 Hz].
    #[arg(long)]
    arm_stale_ms: Option<f64>,
    /// Motor watchdog: stop when the motors' positions are this old, or a motor has not answered
    /// within this time [ms] [default: 10 control ticks, 100.5 ms at 100 Hz].
    #[arg(long)]
    motor_stale_ms: Option<f64>,
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
        let devices = Devices {
            port_base: self.port_base,
            sensor_stale_ms: self.sensor_stale_ms,
            arm_stale_ms: self.arm_stale_ms,
            motor_stale_ms: self.motor_stale_ms,
            ..Devices::new(&self.ur, dxl, &self.interrogator)
        };
        // The flags' names in the messages, as the user typed them.
        devices.config(scenario).map_err(|e| {
            let text = e.to_string();
            let flag = text.split_once(' ').map_or(text.as_str(), |(key, _)| key);
            match flag {
                "sensor_stale_ms" | "arm_stale_ms" | "motor_stale_ms" => {
                    anyhow::anyhow!("--{}", text.replacen('_', "-", 2))
                }
                _ => e,
            }
        })
    }
}

/// Parses `--port-base N`: six ports N..N+5 must fit below 65536.
pub fn port_base(text: &str) -> Result<u16, String> {
    let base: u16 = text.parse().map_err(|e| format!("{e}"))?;
    tendril_run::real::check_port_base(base).map_err(|_| format!("must be 1-{} (ports N..N+5)", u16::MAX - 5))
}
