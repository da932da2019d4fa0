//! MX-106 unit conversions (docs/facts.md#mx-106-units: 4096 ticks/rev (0.088°/tick), 0.229 rpm, 3.36 mA).
//!
//! Position ticks map linearly to radians with 0 ticks = 0 rad; where the mechanism's zero is
//! (e.g. 2048 = mid-range in position mode) is the driver's calibration, not the codec's.

use super::DxlError;
use std::f64::consts::TAU;

/// Encoder ticks per output-shaft revolution (12-bit encoder).
pub const TICKS_PER_REV: f64 = 4096.0;
/// One Goal/Present Velocity unit, in rpm.
pub const VELOCITY_UNIT_RPM: f64 = 0.229;
/// One Goal/Present Current unit, in A.
pub const CURRENT_UNIT_A: f64 = 3.36e-3;

/// Radians per position tick.
pub const RAD_PER_TICK: f64 = TAU / TICKS_PER_REV;
/// rad/s per velocity unit.
pub const RAD_S_PER_VELOCITY_UNIT: f64 = VELOCITY_UNIT_RPM * TAU / 60.0;

/// Position ticks to radians.
pub fn ticks_to_rad(ticks: i32) -> f64 {
    f64::from(ticks) * RAD_PER_TICK
}

/// Radians to the nearest position tick; NaN or beyond the i32 range is an error.
pub fn rad_to_ticks(rad: f64) -> Result<i32, DxlError> {
    to_int(rad / RAD_PER_TICK, "position (rad)", rad)
}

/// Velocity units to rad/s.
pub fn velocity_units_to_rad_s(units: i32) -> f64 {
    f64::from(units) * RAD_S_PER_VELOCITY_UNIT
}

/// rad/s to the nearest velocity unit.
pub fn rad_s_to_velocity_units(rad_s: f64) -> Result<i32, DxlError> {
    to_int(rad_s / RAD_S_PER_VELOCITY_UNIT, "velocity (rad/s)", rad_s)
}

/// Current units to amperes.
pub fn current_units_to_amps(units: i16) -> f64 {
    f64::from(units) * CURRENT_UNIT_A
}

/// Amperes to the nearest current unit (a signed 2-byte field).
pub fn amps_to_current_units(amps: f64) -> Result<i16, DxlError> {
    let units = to_int(amps / CURRENT_UNIT_A, "current (A)", amps)?;
    i16::try_from(units).map_err(|_| DxlError::Unrepresentable { quantity: "current (A)", value: amps })
}

/// Gear ratio of the MX-106 (e-manual "MX-106(2.0)", Specifications: 225 : 1).
pub const GEAR_RATIO: f64 = 225.0;
/// Stall torque at 12 V \[N·m\] (e-manual, Specifications: 8.4 N·m @ 12 V, 5.2 A).
pub const STALL_TORQUE_NM: f64 = 8.4;
/// Stall current at 12 V \[A\] (same line of the e-manual).
pub const STALL_CURRENT_A: f64 = 5.2;
/// The motor's torque constant \[N·m/A\] as the output sees it through the gear: the stall point
/// 8.4 N·m / (225 × 5.2 A) = 7.18 mN·m/A at the motor shaft (gear losses included, as they are in
/// the stall figures). ROBOTIS gives no separate torque constant for the MX-106; this one is
/// derived from its stated stall torque, stall current and gear ratio.
pub const MOTOR_TORQUE_CONSTANT_NM_PER_A: f64 = STALL_TORQUE_NM / (GEAR_RATIO * STALL_CURRENT_A);

/// Motor current \[A\] holding `torque_nm` at the output shaft: torque / (gear ratio × torque
/// constant). Static: friction and the no-load current are not modelled.
pub fn output_torque_to_amps(torque_nm: f64) -> f64 {
    torque_nm / (GEAR_RATIO * MOTOR_TORQUE_CONSTANT_NM_PER_A)
}

/// Present Current (3.36 mA units) for `torque_nm` at the output shaft, within ±`limit` (the
/// Current Limit, in the same units); non-finite torque reads 0.
pub fn present_current_units(torque_nm: f64, limit: u16) -> i16 {
    let units = output_torque_to_amps(torque_nm) / CURRENT_UNIT_A;
    let limit = f64::from(limit.min(i16::MAX as u16));
    if units.is_finite() { units.round().clamp(-limit, limit) as i16 } else { 0 }
}

/// Present Velocity (0.229 rpm units) for `rad_s` at the output shaft, saturated to the field;
/// non-finite reads 0.
pub fn present_velocity_units(rad_s: f64) -> i32 {
    let units = rad_s / RAD_S_PER_VELOCITY_UNIT;
    if units.is_finite() { units.round().clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32 } else { 0 }
}

/// The bus speeds an MX-106 (Protocol 2.0) offers [bit/s], indexed by the value of its Baud Rate
/// register (address 8; ROBOTIS e-manual, MX-106(2.0) control table; 1 = 57 600 is the factory
/// default).
pub const BAUD_RATES: [u32; 8] = [9_600, 57_600, 115_200, 1_000_000, 2_000_000, 3_000_000, 4_000_000, 4_500_000];

/// The Baud Rate register value for `bps`, if the MX-106 offers that speed.
pub fn baud_rate_code(bps: u32) -> Option<u8> {
    BAUD_RATES.iter().position(|&b| b == bps).map(|i| i as u8)
}

fn to_int(scaled: f64, quantity: &'static str, value: f64) -> Result<i32, DxlError> {
    let rounded = scaled.round();
    if rounded.is_finite() && rounded >= f64::from(i32::MIN) && rounded <= f64::from(i32::MAX) {
        Ok(rounded as i32)
    } else {
        Err(DxlError::Unrepresentable { quantity, value })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_revolution_is_4096_ticks() {
        assert_eq!(rad_to_ticks(TAU).unwrap(), 4096);
        assert!((ticks_to_rad(1).to_degrees() - 0.088).abs() < 1e-3);
        assert_eq!(rad_to_ticks(ticks_to_rad(-1234)).unwrap(), -1234);
    }

    #[test]
    fn velocity_and_current_units() {
        // 45 rpm no-load speed at 12 V is about 197 units.
        assert_eq!(rad_s_to_velocity_units(45.0 * TAU / 60.0).unwrap(), 197);
        assert!((current_units_to_amps(1000) - 3.36).abs() < 1e-12);
        assert_eq!(amps_to_current_units(-3.36).unwrap(), -1000);
    }

    #[test]
    fn stall_torque_draws_the_stall_current() {
        assert!((output_torque_to_amps(STALL_TORQUE_NM) - STALL_CURRENT_A).abs() < 1e-12);
        assert!((MOTOR_TORQUE_CONSTANT_NM_PER_A - 7.179e-3).abs() < 1e-6);
        // 5.2 A is 1548 units of 3.36 mA; the Current Limit caps it.
        assert_eq!(present_current_units(STALL_TORQUE_NM, 2047), 1548);
        assert_eq!(present_current_units(-STALL_TORQUE_NM, 1000), -1000);
        assert_eq!(present_current_units(f64::NAN, 2047), 0);
        // 0.8 N on the 16 mm twine spool: 12.8 mN·m, 7.9 mA, 2 units.
        assert_eq!(present_current_units(0.8 * 0.016, 2047), 2);
    }

    #[test]
    fn present_velocity_saturates_and_rounds() {
        assert_eq!(present_velocity_units(45.0 * TAU / 60.0), 197);
        assert_eq!(present_velocity_units(-1e30), i32::MIN);
        assert_eq!(present_velocity_units(f64::INFINITY), 0);
    }

    #[test]
    fn baud_rates_map_to_their_register_values() {
        assert_eq!(baud_rate_code(57_600), Some(1));
        assert_eq!(baud_rate_code(1_000_000), Some(3));
        assert_eq!(baud_rate_code(56_000), None);
    }

    #[test]
    fn nan_and_overflow_are_errors() {
        assert!(rad_to_ticks(f64::NAN).is_err());
        assert!(rad_to_ticks(1e12).is_err());
        assert!(amps_to_current_units(200.0).is_err());
    }
}
