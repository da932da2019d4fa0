//! The virtual UR5e's controller state besides its program: robot mode, local or remote control,
//! PolyScope version, the loaded program, the protective stop's time. The dashboard server shows
//! and changes it ([`crate::dashboard`]).

use tendril_rtde::dashboard::{PolyscopeVersion, RobotMode};

/// How long after a protective stop it may be unlocked \[s\] (the controller's rule).
pub const UNLOCK_DELAY_S: f64 = 5.0;

/// The state the virtual UR starts in (`ServeConfig::ur`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VirtualUrSetup {
    /// Remote control (true) or local control (false; PolyScope 5.6 and later).
    pub remote_control: bool,
    /// Robot mode at start (RUNNING: powered, brakes released).
    pub robot_mode: RobotMode,
    /// The `PolyscopeVersion` reply.
    pub polyscope_version: String,
}

impl Default for VirtualUrSetup {
    fn default() -> Self {
        VirtualUrSetup {
            remote_control: true,
            robot_mode: RobotMode::Running,
            polyscope_version: "URSoftware 5.11.1.108318 (Mar 23 2021)".into(),
        }
    }
}

/// The controller's state the dashboard server shows and changes.
#[derive(Debug, Clone, PartialEq)]
pub struct UrController {
    /// Robot mode.
    pub robot_mode: RobotMode,
    /// Remote control.
    pub remote_control: bool,
    /// The `PolyscopeVersion` reply.
    pub polyscope_version: String,
    /// The program loaded with `load`, if any.
    pub loaded_program: Option<String>,
    /// Twin time of the current protective stop \[s\].
    pub protective_stop_at: Option<f64>,
}

impl UrController {
    /// The controller in `setup`'s state.
    pub fn new(setup: &VirtualUrSetup) -> UrController {
        UrController {
            robot_mode: setup.robot_mode,
            remote_control: setup.remote_control,
            polyscope_version: setup.polyscope_version.clone(),
            loaded_program: None,
            protective_stop_at: None,
        }
    }

    /// Whether this PolyScope has remote control (5.6 and later).
    pub fn has_remote_control(&self) -> bool {
        PolyscopeVersion::parse_reply(&self.polyscope_version).is_some_and(|v| v >= PolyscopeVersion::REMOTE_CONTROL)
    }

    /// Whether programs may be started from outside (remote control, or a PolyScope before 5.6).
    pub fn accepts_programs(&self) -> bool {
        self.remote_control || !self.has_remote_control()
    }
}
