//! The virtual UR5e's IO as RTDE reports it: digital and analog outputs and the speed slider,
//! set by RTDE inputs (SDU ur_rtde's `RTDEIOInterface`) or by a program (`set_standard_digital_out`
//! and the like).
//!
//! RTDE guide semantics: each input package that carries a mask applies its value to the bits set
//! in the mask (`standard_digital_output_mask`/`standard_digital_output`, the configurable and
//! tool pairs, `standard_analog_output_mask` with `_type` and `_0`/`_1`, `speed_slider_mask` bit 0
//! with `speed_slider_fraction`); a mask of 0 changes nothing. Applied once per package, in the
//! order packages arrived ([`tendril_rtde::SharedInputs::take_io_packages`]).
//!
//! Reported: `actual_digital_output_bits` (bits 0-7 standard, 8-15 configurable, 16-17 tool),
//! `actual_configurable_digital_output_bits` (0-7), `standard_analog_output0/1` (volts or amperes:
//! a fraction f is 4 + 16 f mA in current mode, 10 f V in voltage mode), `analog_io_types` (bits 2
//! and 3: output 0 and 1 in voltage mode), `target_speed_fraction`. Nothing is wired to them in the
//! twin: no output changes the cell, and the speed slider does not scale the program's motions.

use tendril_rtde::{RobotOutputs, RtdeValue};
use tendril_urscript::DigitalOut;

/// Sets one digital output bit.
pub fn set_digital_out(o: &mut RobotOutputs, kind: DigitalOut, i: usize, v: bool) {
    let shift = match kind {
        DigitalOut::Standard => 0,
        DigitalOut::Configurable => 8,
        DigitalOut::Tool => 16,
    } + i as u32;
    let bit = 1u64 << shift.min(63);
    o.digital_output_bits = if v { o.digital_output_bits | bit } else { o.digital_output_bits & !bit };
}

/// Sets standard analog output `i` (0 or 1) to fraction `f` of its range, in its current mode.
pub fn set_analog_out(o: &mut RobotOutputs, i: usize, f: f64) {
    let f = f.clamp(0.0, 1.0);
    let voltage = o.analog_io_types >> (2 + i) & 1 == 1;
    let v = if voltage { 10.0 * f } else { 0.004 + 0.016 * f };
    if let Some(slot) = o.standard_analog_output.get_mut(i) {
        *slot = v;
    }
}

fn int(v: Option<&RtdeValue>) -> u64 {
    match v {
        Some(RtdeValue::Uint8(x)) => (*x).into(),
        Some(RtdeValue::Uint32(x)) => (*x).into(),
        Some(RtdeValue::Int32(x)) => *x as u64,
        _ => 0,
    }
}

fn double(v: Option<&RtdeValue>) -> Option<f64> {
    match v {
        Some(RtdeValue::Double(x)) => Some(*x),
        _ => None,
    }
}

/// Applies one input package's IO fields (name, value) to the outputs.
pub fn apply_io_package(package: &[(String, RtdeValue)], o: &mut RobotOutputs) {
    let get = |name: &str| package.iter().find(|(n, _)| n == name).map(|(_, v)| v);
    for (kind, prefix, count) in [
        (DigitalOut::Standard, "standard", 8),
        (DigitalOut::Configurable, "configurable", 8),
        (DigitalOut::Tool, "tool", 2),
    ] {
        let mask = int(get(&format!("{prefix}_digital_output_mask")));
        let value = int(get(&format!("{prefix}_digital_output")));
        for i in 0..count {
            if mask >> i & 1 == 1 {
                set_digital_out(o, kind, i, value >> i & 1 == 1);
            }
        }
    }
    let mask = int(get("standard_analog_output_mask"));
    if mask != 0 {
        let types = int(get("standard_analog_output_type"));
        for i in 0..2 {
            if mask >> i & 1 == 1 {
                // The type field's bit i: output i in voltage mode.
                let bit = 1u32 << (2 + i);
                o.analog_io_types =
                    if types >> i & 1 == 1 { o.analog_io_types | bit } else { o.analog_io_types & !bit };
                if let Some(f) = double(get(&format!("standard_analog_output_{i}"))) {
                    set_analog_out(o, i, f);
                }
            }
        }
    }
    if int(get("speed_slider_mask")) & 1 == 1
        && let Some(f) = double(get("speed_slider_fraction"))
        && f.is_finite()
    {
        o.target_speed_fraction = f.clamp(0.0, 1.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn package(items: &[(&str, RtdeValue)]) -> Vec<(String, RtdeValue)> {
        items.iter().map(|(n, v)| (n.to_string(), *v)).collect()
    }

    #[test]
    fn masks_select_the_bits_a_package_changes() {
        let mut o = RobotOutputs::default();
        apply_io_package(
            &package(&[
                ("standard_digital_output_mask", RtdeValue::Uint8(0b1010)),
                ("standard_digital_output", RtdeValue::Uint8(0xFF)),
            ]),
            &mut o,
        );
        assert_eq!(o.digital_output_bits, 0b1010);
        apply_io_package(
            &package(&[
                ("tool_digital_output_mask", RtdeValue::Uint8(1)),
                ("tool_digital_output", RtdeValue::Uint8(1)),
            ]),
            &mut o,
        );
        assert_eq!(o.digital_output_bits, 0b1010 | 1 << 16);
        apply_io_package(
            &package(&[
                ("standard_digital_output_mask", RtdeValue::Uint8(0b10)),
                ("standard_digital_output", RtdeValue::Uint8(0)),
            ]),
            &mut o,
        );
        assert_eq!(o.digital_output_bits, 0b1000 | 1 << 16);
        // Mask 0: nothing changes.
        apply_io_package(
            &package(&[("speed_slider_mask", RtdeValue::Uint32(0)), ("speed_slider_fraction", RtdeValue::Double(0.2))]),
            &mut o,
        );
        assert_eq!(o.target_speed_fraction, 1.0);
        apply_io_package(
            &package(&[("speed_slider_mask", RtdeValue::Uint32(1)), ("speed_slider_fraction", RtdeValue::Double(0.2))]),
            &mut o,
        );
        assert_eq!(o.target_speed_fraction, 0.2);
    }

    #[test]
    fn analog_outputs_report_amperes_or_volts() {
        let mut o = RobotOutputs::default();
        apply_io_package(
            &package(&[
                ("standard_analog_output_mask", RtdeValue::Uint8(0b11)),
                ("standard_analog_output_type", RtdeValue::Uint8(0b10)),
                ("standard_analog_output_0", RtdeValue::Double(0.5)),
                ("standard_analog_output_1", RtdeValue::Double(0.25)),
            ]),
            &mut o,
        );
        assert!((o.standard_analog_output[0] - 0.012).abs() < 1e-12, "current mode: 12 mA");
        assert!((o.standard_analog_output[1] - 2.5).abs() < 1e-12, "voltage mode: 2.5 V");
        assert_eq!(o.analog_io_types, 1 << 3);
    }
}
