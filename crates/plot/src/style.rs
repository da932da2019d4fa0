//! Shared look: the embedded font, text sizes, colours and number formats.

use plotters::style::{FontStyle, RGBColor};

/// The font family every chart asks for; registered from the embedded DejaVu Sans.
pub const FONT: &str = "sans-serif";

/// Registers DejaVu Sans (regular, bold) as [`FONT`] once. DejaVu is under the Bitstream Vera
/// licence (free to embed); the `dejavu` crate ships the TTF files, so no system font is needed.
pub fn register_fonts() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The bytes are the crate's own TTFs; a parse failure would only drop text, never panic.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Title text size \[px\].
pub const TITLE: u32 = 26;
/// Panel caption size \[px\].
pub const CAPTION: u32 = 20;
/// Axis description size \[px\].
pub const AXIS: u32 = 18;
/// Tick label and legend size \[px\].
pub const LABEL: u32 = 15;
/// Small annotation size \[px\].
pub const SMALL: u32 = 13;

/// Categorical palette (Okabe–Ito, colour-blind safe), for series.
pub const SERIES: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(120, 120, 120),
    RGBColor(240, 228, 66),
];

/// Good outcome (held, stable).
pub const GOOD: RGBColor = RGBColor(46, 160, 67);
/// Bad outcome (dropped, diverged).
pub const BAD: RGBColor = RGBColor(200, 40, 40);
/// Warning outcome (oscillating, penetration).
pub const WARN: RGBColor = RGBColor(240, 170, 20);
/// Other failure (lost grasp, dropped while oscillating).
pub const OTHER: RGBColor = RGBColor(130, 60, 160);
/// Error / no value.
pub const NONE: RGBColor = RGBColor(200, 200, 200);

/// Linear blend of two colours, `t` in [0, 1] from `a` to `b`.
pub fn blend(a: RGBColor, b: RGBColor, t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let m = |x: u8, y: u8| (f64::from(x) + (f64::from(y) - f64::from(x)) * t).round() as u8;
    RGBColor(m(a.0, b.0), m(a.1, b.1), m(a.2, b.2))
}

/// Black or white, whichever reads better on `bg`.
pub fn text_on(bg: RGBColor) -> RGBColor {
    let luma = 0.299 * f64::from(bg.0) + 0.587 * f64::from(bg.1) + 0.114 * f64::from(bg.2);
    if luma > 140.0 { RGBColor(0, 0, 0) } else { RGBColor(255, 255, 255) }
}

/// A number with about three significant digits, without trailing noise (0.001, 12.5, 3e-5).
pub fn num(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if a == 0.0 {
        "0".to_string()
    } else if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.2e}");
        // 1.00e-4 -> 1e-4, 2.50e-4 -> 2.5e-4
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') { m.trim_end_matches('0').trim_end_matches('.') } else { m };
        format!("{m}e{e}")
    } else {
        let digits = (2 - a.log10().floor() as i32).clamp(0, 6) as usize;
        let s = format!("{v:.digits$}");
        if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s }
    }
}

/// A time step in readable units (0.002 -> "2 ms", 5e-5 -> "50 µs").
pub fn timestep(dt_s: f64) -> String {
    if dt_s >= 1.0 {
        format!("{} s", num(dt_s))
    } else if dt_s >= 1e-3 {
        format!("{} ms", num(dt_s * 1e3))
    } else {
        format!("{} µs", num(dt_s * 1e6))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_well() {
        assert_eq!(num(0.001), "0.001");
        assert_eq!(num(12.5), "12.5");
        assert_eq!(num(0.0001), "1e-4");
        assert_eq!(num(2.5e-5), "2.5e-5");
        assert_eq!(num(150.0), "150");
        assert_eq!(timestep(0.002), "2 ms");
        assert_eq!(timestep(5e-5), "50 µs");
    }
}
