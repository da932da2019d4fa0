//! Scenario section `[hardware]`: what differs between one set of real devices and another (the
//! motors' bus IDs and speed, where the gratings' peaks sit). `tendril run --hardware real` drives
//! the devices with it, and `tendril serve` makes the virtual devices answer the same way.
//!
//! ```toml
//! [hardware]
//! growth_id = 1
//! twine_id = 2
//! dxl_baud = 57600
//! [hardware.fbg]
//! channel = 1
//! fbg1_min_nm = 1535.0
//! [[hardware.fbg.pads]]     # a sensor array's further pad 1 (optional: derived from [array])
//! channel = 1
//! fbg1_min_nm = 1500.0
//! fbg1_max_nm = 1533.1
//! ```

use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};
use tendril_dynamixel::device::MAX_DEVICE_ID;
use tendril_dynamixel::units::{BAUD_RATES, baud_rate_code};
use tendril_hyperion::FbgWindows;

/// The devices' settings. `Default` is a factory-fresh pair of MX-106 with the twine motor
/// renumbered, and the paper's gratings on channel 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HardwareConfig {
    /// Dynamixel ID of the growth motor [-]: 1, the MX-106's factory ID (ROBOTIS e-manual).
    pub growth_id: u8,
    /// Dynamixel ID of the twine motor [-]: 2. Both motors leave the factory as ID 1, so one must
    /// be renumbered (Dynamixel Wizard) before they share a bus.
    pub twine_id: u8,
    /// Dynamixel bus speed [bit/s]: 57 600, the MX-106's factory setting. One of the speeds its Baud
    /// Rate register offers (9 600, 57 600, 115 200, 1 M, 2 M, 3 M, 4 M, 4.5 M). A sync write and
    /// a sync read of both motors take about 6 ms of wire time at 57 600: run a 500 Hz loop at
    /// 1 M or more (set the motors' Baud Rate first).
    pub dxl_baud: u32,
    /// Which interrogator channel and wavelength windows hold FBG1 and FBG2 \[nm\] (and a sensor
    /// array's further pads' gratings).
    pub fbg: FbgWindows,
}

impl Default for HardwareConfig {
    fn default() -> Self {
        HardwareConfig { growth_id: 1, twine_id: 2, dxl_baud: 57_600, fbg: FbgWindows::default() }
    }
}

impl HardwareConfig {
    /// The motors' IDs, [growth, twine].
    pub fn motor_ids(&self) -> [u8; 2] {
        [self.growth_id, self.twine_id]
    }
}

impl Validate for HardwareConfig {
    fn validate(&self, at: &mut Checker) {
        for (name, id) in [("growth_id", self.growth_id), ("twine_id", self.twine_id)] {
            // 253-255 are reserved or the broadcast ID (Protocol 2.0).
            at.require(name, id <= MAX_DEVICE_ID, || format!("must be 0-{MAX_DEVICE_ID}, got {id}"));
        }
        at.require("twine_id", self.twine_id != self.growth_id, || {
            format!("must differ from growth_id ({}): two motors cannot share a bus ID", self.growth_id)
        });
        at.require("dxl_baud", baud_rate_code(self.dxl_baud).is_some(), || {
            format!("must be a speed the MX-106 offers, one of {BAUD_RATES:?}, got {}", self.dxl_baud)
        });
        at.section("fbg", &self.fbg);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn first_error(h: HardwareConfig) -> Option<String> {
        let mut at = Checker::default();
        h.validate(&mut at);
        at.into_first_error().map(|(key, _)| key)
    }

    #[test]
    fn the_defaults_are_valid_and_bad_values_name_their_key() {
        assert_eq!(first_error(HardwareConfig::default()), None);
        let d = HardwareConfig::default();
        assert_eq!(first_error(HardwareConfig { twine_id: 1, ..d }).as_deref(), Some("twine_id"));
        assert_eq!(first_error(HardwareConfig { growth_id: 254, ..d }).as_deref(), Some("growth_id"));
        assert_eq!(first_error(HardwareConfig { dxl_baud: 56_000, ..d }).as_deref(), Some("dxl_baud"));
        let fbg = FbgWindows { channel: 0, ..d.fbg };
        assert_eq!(first_error(HardwareConfig { fbg, ..d }).as_deref(), Some("fbg.channel"));
    }
}
