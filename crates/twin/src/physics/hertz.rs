//! Hertz's elastic contact: the pressure under a contact of known normal force, and the
//! compression of a sphere between two flat plates.
//!
//! Two bodies pressed together by a normal force `F` touch over a small patch whose pressure is
//! Hertz's ellipsoidal distribution, `p(ρ) = p₀ √(1 − ρ²/a²)` (K. L. Johnson, *Contact Mechanics*,
//! Cambridge University Press 1985, ch. 4; `docs/facts.md#hertz-contact`). With the
//! contact modulus `E*` (`1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂`) and the effective radius `R`
//! (`1/R` the sum of the bodies' curvatures):
//!
//! - point contact (sphere-like): `a = (3FR / 4E*)^⅓`, `p₀ = 3F / (2πa²)`, approach
//!   `d = a² / R`;
//! - line contact (a cylinder along a length `L`): half-width `b = √(4F′R / πE*)`,
//!   `p₀ = 2F′ / (πb)`, `F′ = F / L`.
//!
//! A sphere of radius `R` between two rigid plates touches each with the same force, each
//! contact approaching by half the plates' travel `δ`: `F = (4/3) E* √R (δ/2)^{3/2}` (the ASAE
//! S368 compression test of convex food materials rests on the same equations).
//!
//! The twin's produce items are interpolated flex bodies that cannot carry a contact's local
//! indentation (`docs/studies/produce.md`): their contact pressure is Hertz's for the normal
//! force MuJoCo computes, per patch (the contacts one finger geom makes with the item).

use std::f64::consts::PI;

/// The contact modulus `E*` of two elastic bodies \[Pa\]: `1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂`.
/// An infinite modulus is a rigid body.
pub fn contact_modulus_pa(e1_pa: f64, nu1: f64, e2_pa: f64, nu2: f64) -> f64 {
    let compliance = |e: f64, nu: f64| if e.is_infinite() { 0.0 } else { (1.0 - nu * nu) / e };
    1.0 / (compliance(e1_pa, nu1) + compliance(e2_pa, nu2))
}

/// What Hertz's theory says of one contact patch.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Patch {
    /// Peak pressure, at the patch's centre \[Pa\].
    pub peak_pa: f64,
    /// Radius of a point contact's circle, or half-width of a line contact's strip \[m\].
    pub half_width_m: f64,
    /// Area of the patch \[m²\].
    pub area_m2: f64,
    /// Area where the pressure exceeds the threshold it was asked about \[m²\] (0 when the peak
    /// stays below it).
    pub area_above_m2: f64,
}

/// The geometry of a contact: point (both curvatures finite) or line (one curvature zero, a
/// cylinder on a flat face along `length_m`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Geometry {
    /// Effective radius `R = 1/√(κ₁κ₂)` of the two bodies' summed principal curvatures \[m\].
    Point {
        /// Effective radius \[m\].
        radius_m: f64,
    },
    /// A cylinder of effective radius `radius_m` touching along `length_m`.
    Line {
        /// Effective radius across the line \[m\].
        radius_m: f64,
        /// Length of the line of contact \[m\].
        length_m: f64,
    },
}

impl Geometry {
    /// The contact between two bodies of principal curvatures `a` and `b` \[1/m\] (each body's
    /// two, aligned: the worst case of two cylinders' orientations) touching over at most
    /// `length_m` along a direction without curvature.
    pub fn of_curvatures(a: [f64; 2], b: [f64; 2], length_m: f64) -> Geometry {
        let k1 = a[0] + b[0];
        let k2 = a[1] + b[1];
        let (big, small) = if k1 >= k2 { (k1, k2) } else { (k2, k1) };
        // A curvature below a hundredth of the other's: a line contact (a cylinder on a face).
        if small <= 0.01 * big {
            Geometry::Line { radius_m: 1.0 / big, length_m }
        } else {
            Geometry::Point { radius_m: 1.0 / (k1 * k2).sqrt() }
        }
    }
}

/// Hertz's patch for a normal force `force_n` \[N\] over `geometry` with contact modulus
/// `modulus_pa` (`E*`), and the area where the pressure exceeds `threshold_pa`.
pub fn patch(force_n: f64, geometry: Geometry, modulus_pa: f64, threshold_pa: f64) -> Patch {
    if force_n.is_nan() || force_n <= 0.0 {
        return Patch::default();
    }
    match geometry {
        Geometry::Point { radius_m } => {
            let a = (3.0 * force_n * radius_m / (4.0 * modulus_pa)).cbrt();
            let peak = 3.0 * force_n / (2.0 * PI * a * a);
            // p > p_t where 1 − ρ²/a² > (p_t/p₀)²: a disc of radius a √(1 − (p_t/p₀)²).
            let above = if peak > threshold_pa { PI * a * a * (1.0 - (threshold_pa / peak).powi(2)) } else { 0.0 };
            Patch { peak_pa: peak, half_width_m: a, area_m2: PI * a * a, area_above_m2: above }
        }
        Geometry::Line { radius_m, length_m } => {
            let per_length = force_n / length_m;
            let b = (4.0 * per_length * radius_m / (PI * modulus_pa)).sqrt();
            let peak = 2.0 * per_length / (PI * b);
            let above = if peak > threshold_pa {
                2.0 * b * length_m * (1.0 - (threshold_pa / peak).powi(2)).sqrt()
            } else {
                0.0
            };
            Patch { peak_pa: peak, half_width_m: b, area_m2: 2.0 * b * length_m, area_above_m2: above }
        }
    }
}

/// Force on each of two rigid plates squeezing an elastic sphere of radius `radius_m` by a total
/// travel `travel_m` \[N\] (each contact approaches by half of it), contact modulus `modulus_pa`.
pub fn plates_force_n(radius_m: f64, modulus_pa: f64, travel_m: f64) -> f64 {
    let d = (travel_m / 2.0).max(0.0);
    4.0 / 3.0 * modulus_pa * radius_m.sqrt() * d.powf(1.5)
}

/// The plates' total travel that squeezes the sphere with `force_n` \[m\] (the inverse of
/// [`plates_force_n`]).
pub fn plates_travel_m(radius_m: f64, modulus_pa: f64, force_n: f64) -> f64 {
    2.0 * (3.0 * force_n.max(0.0) / (4.0 * modulus_pa * radius_m.sqrt())).powf(2.0 / 3.0)
}

/// Peak pressure \[Pa\] and contact radius \[m\] at each plate after a total travel `travel_m`:
/// `p₀ = (2E*/π) √(d/R)`, `a = √(R d)`, `d = δ/2`.
pub fn plates_patch(radius_m: f64, modulus_pa: f64, travel_m: f64) -> (f64, f64) {
    let d = (travel_m / 2.0).max(0.0);
    (2.0 * modulus_pa / PI * (d / radius_m).sqrt(), (radius_m * d).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_contact_has_the_textbook_radius_and_pressure() {
        // Worked by hand from a³ = 3FR/4E*: 1 N, R = 15 mm, E* = 0.5 MPa.
        let p = patch(1.0, Geometry::Point { radius_m: 0.015 }, 0.5e6, f64::INFINITY);
        let a = (3.0 * 0.015 / (4.0 * 0.5e6_f64)).cbrt();
        assert!((p.half_width_m - a).abs() < 1e-15 && (a - 2.823e-3).abs() < 1e-6, "{a}");
        assert!((p.peak_pa - 3.0 / (2.0 * PI * a * a)).abs() < 1e-9);
        // The pressure integrates to the force: ∫ p₀ √(1 − ρ²/a²) 2πρ dρ = (2/3) π a² p₀.
        assert!((2.0 / 3.0 * PI * a * a * p.peak_pa - 1.0).abs() < 1e-12);
        assert_eq!(p.area_above_m2, 0.0);
    }

    #[test]
    fn the_area_above_a_threshold_shrinks_to_nothing_at_the_peak() {
        let g = Geometry::Point { radius_m: 0.01 };
        let p = patch(2.0, g, 1e6, 0.0);
        assert!((p.area_above_m2 - p.area_m2).abs() < 1e-18, "everything is above zero");
        let half = patch(2.0, g, 1e6, p.peak_pa * 0.5_f64.sqrt());
        assert!((half.area_above_m2 - p.area_m2 / 2.0).abs() < 1e-15);
        assert_eq!(patch(2.0, g, 1e6, p.peak_pa * 1.000001).area_above_m2, 0.0);
    }

    #[test]
    fn a_line_contact_integrates_to_its_force() {
        let (f, l) = (3.0, 0.02);
        let p = patch(f, Geometry::Line { radius_m: 0.0125, length_m: l }, 0.4e6, f64::INFINITY);
        // ∫ p₀ √(1 − x²/b²) dx over [−b, b] = π b p₀ / 2 per length.
        assert!((PI * p.half_width_m * p.peak_pa / 2.0 * l - f).abs() < 1e-12);
    }

    #[test]
    fn plates_force_and_travel_are_inverse_and_the_patch_is_hertz() {
        let (r, e) = (0.015, 0.6e6);
        let travel = plates_travel_m(r, e, 1.0);
        assert!((plates_force_n(r, e, travel) - 1.0).abs() < 1e-12);
        // The plate's patch from the force equals the one from the travel.
        let p = patch(1.0, Geometry::Point { radius_m: r }, e, f64::INFINITY);
        let (peak, a) = plates_patch(r, e, travel);
        assert!((p.peak_pa / peak - 1.0).abs() < 1e-12 && (p.half_width_m / a - 1.0).abs() < 1e-12);
    }

    #[test]
    fn curvatures_pick_the_contact_geometry() {
        // A 15 mm sphere on a flat face: a point of radius 15 mm.
        match Geometry::of_curvatures([1.0 / 0.015; 2], [0.0; 2], 0.02) {
            Geometry::Point { radius_m } => assert!((radius_m - 0.015).abs() < 1e-15),
            g => panic!("{g:?}"),
        }
        // A cylinder on a flat face: a line along the face's extent.
        assert_eq!(
            Geometry::of_curvatures([1.0 / 0.0125, 0.0], [0.0; 2], 0.02),
            Geometry::Line { radius_m: 0.0125, length_m: 0.02 }
        );
        // A 1.5 mm bump on a 15 mm sphere: 1/R = 1/1.5 + 1/15 per direction.
        match Geometry::of_curvatures([1.0 / 0.015; 2], [1.0 / 0.0015; 2], 0.02) {
            Geometry::Point { radius_m } => assert!((radius_m - 1.0 / (1.0 / 0.015 + 1.0 / 0.0015)).abs() < 1e-15),
            g => panic!("{g:?}"),
        }
        assert!(contact_modulus_pa(1e6, 0.5, f64::INFINITY, 0.3) > 1.33e6);
    }
}
