//! The controller settings a program changes (URScript manual names): the TCP (`set_tcp`), the
//! payload (`set_payload`, `set_target_payload`), gravity (`set_gravity`), the tool voltage
//! (`set_tool_voltage`), the force/torque sensor's zero (`zero_ftsensor`) and freedrive
//! (`freedrive_mode`). The program owns them; the controller around it reads them after each
//! cycle ([`crate::Interpreter::setup`]) to report them (RTDE `tcp_offset`, `payload`,
//! `target_gravity`, `tool_output_voltage`, the TCP force, the primary interface's control mode).
//!
//! The payload and gravity are what the controller is told, not what the twin's physics does:
//! the twin's arm carries whatever the scene puts in its hand.

use super::value::Value;

/// URScript's default gravity vector \[m/s²\] (base frame, towards the earth's centre).
pub const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, 9.82];
/// Heaviest payload accepted \[kg\]: the UR5e's rated payload (5 kg, UR5e datasheet) with a
/// margin; the controller refuses heavier ones.
pub const MAX_PAYLOAD_KG: f64 = 6.0;

/// What the program set.
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// TCP offset from the flange: x, y, z \[m\] and rotation vector \[rad\].
    pub tcp: [f64; 6],
    /// Payload mass \[kg\].
    pub payload_kg: f64,
    /// Payload centre of gravity from the flange \[m\].
    pub payload_cog: [f64; 3],
    /// Payload inertia \[Ixx, Iyy, Izz, Ixy, Ixz, Iyz\] \[kg·m²\].
    pub payload_inertia: [f64; 6],
    /// Gravity in the base frame \[m/s²\].
    pub gravity: [f64; 3],
    /// Tool output voltage \[V\] (0, 12 or 24).
    pub tool_voltage: i32,
    /// The force/torque reading `zero_ftsensor` took as zero \[N, N·m\].
    pub ft_zero: [f64; 6],
    /// In freedrive mode.
    pub freedrive: bool,
}

impl Default for Setup {
    fn default() -> Self {
        Setup {
            tcp: [0.0; 6],
            payload_kg: 0.0,
            payload_cog: [0.0; 3],
            payload_inertia: [0.0; 6],
            gravity: DEFAULT_GRAVITY,
            tool_voltage: 0,
            ft_zero: [0.0; 6],
            freedrive: false,
        }
    }
}

/// Three numbers from a list (a centre of gravity, a gravity vector).
pub fn three(name: &str, what: &str, v: &Value) -> Result<[f64; 3], String> {
    match v {
        Value::List(l) if l.len() == 3 => {
            let mut out = [0.0; 3];
            for (o, x) in out.iter_mut().zip(l) {
                *o = x.num(&format!("{name}'s `{what}`"))?;
                if !o.is_finite() {
                    return Err(format!("{name}: `{what}` is not finite"));
                }
            }
            Ok(out)
        }
        other => Err(format!("{name}: `{what}` must be a list of 3 numbers, got {}", other.describe())),
    }
}

/// Checks a payload mass.
pub fn payload_mass(name: &str, m: f64) -> Result<f64, String> {
    if m.is_finite() && (0.0..=MAX_PAYLOAD_KG).contains(&m) {
        Ok(m)
    } else {
        Err(format!("{name}: mass {m} kg is not in [0, {MAX_PAYLOAD_KG}]"))
    }
}
