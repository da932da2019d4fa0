//! Joint-space point-to-point moves with a synchronised trapezoidal velocity profile.
//!
//! All joints start and stop together and follow the same normalised profile, so the tool moves
//! along a straight line in joint space. The joint that travels furthest sets the profile; its
//! speed and acceleration stay within [`JointLimits`] (the paper's transfer: 45 °/s, 15 °/s²).

use serde::{Deserialize, Serialize};
use tendril_cell::ARM_JOINTS;
use tendril_config::{Checker, Validate};

/// Per-joint speed and acceleration bounds (TOML `[task.limits]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JointLimits {
    /// Largest joint speed [°/s]. Paper Sec. V-B: 45.
    pub max_speed_deg_s: f64,
    /// Largest joint acceleration [°/s²]. Paper Sec. V-B: 15.
    pub max_accel_deg_s2: f64,
}

impl Default for JointLimits {
    fn default() -> Self {
        JointLimits { max_speed_deg_s: 45.0, max_accel_deg_s2: 15.0 }
    }
}

impl Validate for JointLimits {
    fn validate(&self, at: &mut Checker) {
        // The UR5e's joints reach 180 °/s (docs/facts.md#ur5e-joint-speed); faster targets would not be followed.
        at.in_range("max_speed_deg_s", self.max_speed_deg_s, 1e-3, 180.0);
        // 1e4 °/s²: reaches the UR5e's top joint speed in 18 ms, beyond what its drives deliver
        // with a payload; below 1e-3 °/s² a move would take days.
        at.in_range("max_accel_deg_s2", self.max_accel_deg_s2, 1e-3, 1e4);
    }
}

/// A planned move from one joint configuration to another.
#[derive(Debug, Clone, PartialEq)]
pub struct JointMove {
    from: [f64; ARM_JOINTS],
    to: [f64; ARM_JOINTS],
    duration_s: f64,
    /// Time spent accelerating (and, symmetrically, decelerating) [s].
    ramp_s: f64,
    /// Peak rate of the normalised path parameter s ∈ [0, 1] [1/s].
    peak_rate: f64,
}

impl JointMove {
    /// Plans a move within `limits` that lasts at least `min_duration_s`.
    ///
    /// Without a minimum duration the move is time-optimal. A move stretched beyond that is
    /// slowed as a whole, acceleration included, the way a motion planner's velocity and
    /// acceleration scaling does: it accelerates over its first third, cruises, and brakes over
    /// its last third. (Full acceleration to a slow cruise would jolt the hand at the start and
    /// load a freshly lifted object in a fraction of a second.) Angles in radians.
    pub fn plan(
        from: [f64; ARM_JOINTS],
        to: [f64; ARM_JOINTS],
        limits: &JointLimits,
        min_duration_s: f64,
    ) -> JointMove {
        let span = from.iter().zip(&to).map(|(a, b)| (b - a).abs()).fold(0.0, f64::max);
        if span == 0.0 {
            return JointMove { from, to, duration_s: min_duration_s.max(0.0), ramp_s: 0.0, peak_rate: 0.0 };
        }
        let v = limits.max_speed_deg_s.to_radians() / span; // normalised speed limit [1/s]
        let a = limits.max_accel_deg_s2.to_radians() / span; // normalised acceleration limit [1/s²]
        // Fastest profile: triangular when the speed limit is never reached, trapezoidal otherwise.
        let fastest = if v * v / a >= 1.0 { 2.0 / a.sqrt() } else { 1.0 / v + v / a };
        let duration_s = fastest.max(min_duration_s);
        // Thirds profile: ramps of T/3 reach the rate 1.5/T with acceleration 4.5/T².
        let (third_rate, third_accel) = (1.5 / duration_s, 4.5 / duration_s.powi(2));
        if third_rate <= v && third_accel <= a {
            return JointMove { from, to, duration_s, ramp_s: duration_s / 3.0, peak_rate: third_rate };
        }
        // Close to the fastest move: full acceleration, cruise rate w from 1 = w (T − w / a).
        let disc = (a * duration_s).powi(2) - 4.0 * a;
        let peak_rate = (a * duration_s - disc.max(0.0).sqrt()) / 2.0;
        JointMove { from, to, duration_s, ramp_s: peak_rate / a, peak_rate }
    }

    /// How long the move takes \[s\].
    pub fn duration_s(&self) -> f64 {
        self.duration_s
    }

    /// The target configuration.
    pub fn end(&self) -> [f64; ARM_JOINTS] {
        self.to
    }

    /// Largest planned joint speed over the move and the joints [rad/s].
    pub fn peak_speed_rad_s(&self) -> f64 {
        self.peak_rate * self.span_rad()
    }

    /// Largest planned joint acceleration over the move and the joints [rad/s²].
    pub fn peak_accel_rad_s2(&self) -> f64 {
        if self.ramp_s > 0.0 { self.peak_rate / self.ramp_s * self.span_rad() } else { 0.0 }
    }

    /// Largest joint travel \[rad\].
    fn span_rad(&self) -> f64 {
        self.from.iter().zip(&self.to).map(|(a, b)| (b - a).abs()).fold(0.0, f64::max)
    }

    /// Path parameter s ∈ [0, 1] and its rate at time `t` after the start.
    fn progress(&self, t: f64) -> (f64, f64) {
        if self.peak_rate == 0.0 {
            return (if t >= self.duration_s { 1.0 } else { 0.0 }, 0.0);
        }
        let (w, ta, tt) = (self.peak_rate, self.ramp_s, self.duration_s);
        let a = w / ta;
        let t = t.clamp(0.0, tt);
        if t < ta {
            (0.5 * a * t * t, a * t)
        } else if t <= tt - ta {
            (0.5 * a * ta * ta + w * (t - ta), w)
        } else {
            let left = tt - t;
            (1.0 - 0.5 * a * left * left, a * left)
        }
    }

    /// Planned joint accelerations [rad/s²] at time `t` after the start: constant while the
    /// profile ramps up or down, zero while it cruises and outside the move.
    pub fn acceleration(&self, t: f64) -> [f64; ARM_JOINTS] {
        let (w, ta, tt) = (self.peak_rate, self.ramp_s, self.duration_s);
        let path_accel = if w == 0.0 || ta <= 0.0 || !(0.0..tt).contains(&t) {
            0.0
        } else if t < ta {
            w / ta
        } else if t <= tt - ta {
            0.0
        } else {
            -w / ta
        };
        std::array::from_fn(|j| path_accel * (self.to[j] - self.from[j]))
    }

    /// Joint positions \[rad\] and velocities [rad/s] at time `t` after the start.
    pub fn sample(&self, t: f64) -> ([f64; ARM_JOINTS], [f64; ARM_JOINTS]) {
        let (s, rate) = self.progress(t);
        let mut q = [0.0; ARM_JOINTS];
        let mut qd = [0.0; ARM_JOINTS];
        for j in 0..ARM_JOINTS {
            let delta = self.to[j] - self.from[j];
            q[j] = self.from[j] + s * delta;
            qd[j] = rate * delta;
        }
        (q, qd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEG: f64 = std::f64::consts::PI / 180.0;

    fn peak_speed_and_accel(m: &JointMove) -> (f64, f64) {
        let dt = 1e-3;
        let (mut vmax, mut amax, mut prev) = (0.0f64, 0.0f64, 0.0);
        let mut t = 0.0;
        while t <= m.duration_s() {
            let v = m.sample(t).1.iter().map(|v| v.abs()).fold(0.0, f64::max);
            vmax = vmax.max(v);
            if t > 0.0 {
                amax = amax.max((v - prev).abs() / dt);
            }
            prev = v;
            t += dt;
        }
        (vmax / DEG, amax / DEG)
    }

    #[test]
    fn long_move_cruises_at_the_speed_limit() {
        let to = [180.0 * DEG, 0.0, 0.0, 0.0, 0.0, 0.0];
        let m = JointMove::plan([0.0; 6], to, &JointLimits::default(), 0.0);
        // Two 3 s ramps cover 135°, the remaining 45° at 45 °/s take 1 s.
        assert!((m.duration_s() - 7.0).abs() < 1e-9, "{}", m.duration_s());
        let (v, a) = peak_speed_and_accel(&m);
        assert!((v - 45.0).abs() < 0.1 && a <= 15.0 + 0.1, "v {v} a {a}");
        assert_eq!(m.sample(m.duration_s()).0, to);
    }

    #[test]
    fn short_move_is_triangular_and_slow_moves_stretch() {
        let to = [0.0, 20.0 * DEG, -10.0 * DEG, 0.0, 0.0, 0.0];
        let m = JointMove::plan([0.0; 6], to, &JointLimits::default(), 0.0);
        assert!((m.duration_s() - 2.0 * (20.0f64 / 15.0).sqrt()).abs() < 1e-9);
        let slow = JointMove::plan([0.0; 6], to, &JointLimits::default(), 10.0);
        assert_eq!(slow.duration_s(), 10.0);
        let (v, a) = peak_speed_and_accel(&slow);
        // Stretched moves scale acceleration too: ramps of a third, 20° × 4.5 / 10² = 0.9 °/s².
        assert!((v - 3.0).abs() < 0.01 && (a - 0.9).abs() < 0.05, "v {v} a {a}");
        // Joints stay synchronised: the second joint is always at minus half the first.
        let (q, _) = slow.sample(3.3);
        assert!((q[2] + 0.5 * q[1]).abs() < 1e-12);
    }

    #[test]
    fn peaks_are_those_of_the_profile() {
        let to = [0.0, 20.0 * DEG, -10.0 * DEG, 0.0, 0.0, 0.0];
        let fast = JointMove::plan([0.0; 6], to, &JointLimits::default(), 0.0);
        let (v, a) = peak_speed_and_accel(&fast);
        assert!((fast.peak_accel_rad_s2() / DEG - 15.0).abs() < 1e-9, "{}", fast.peak_accel_rad_s2() / DEG);
        assert!((fast.peak_speed_rad_s() / DEG - v).abs() < 0.05 && a <= 15.1);
        let slow = JointMove::plan([0.0; 6], to, &JointLimits::default(), 10.0);
        assert!((slow.peak_accel_rad_s2() / DEG - 0.9).abs() < 1e-9);
        assert!((slow.peak_speed_rad_s() / DEG - 3.0).abs() < 1e-9);
        assert_eq!(JointMove::plan([0.0; 6], [0.0; 6], &JointLimits::default(), 1.0).peak_accel_rad_s2(), 0.0);
    }

    #[test]
    fn zero_move_holds_still_for_its_duration() {
        let q = [0.1; 6];
        let m = JointMove::plan(q, q, &JointLimits::default(), 2.0);
        assert_eq!(m.duration_s(), 2.0);
        assert_eq!(m.sample(1.0), (q, [0.0; 6]));
        assert_eq!(m.acceleration(1.0), [0.0; 6]);
    }

    #[test]
    fn acceleration_is_the_derivative_of_the_planned_velocity() {
        let to = [0.0, 20.0 * DEG, -10.0 * DEG, 0.0, 0.0, 0.0];
        for min_s in [0.0, 10.0] {
            let m = JointMove::plan([0.0; 6], to, &JointLimits::default(), min_s);
            let (h, tt) = (1e-6, m.duration_s());
            for t in [0.05 * tt, 0.3 * tt, 0.5 * tt, 0.7 * tt, 0.95 * tt] {
                let (v0, v1) = (m.sample(t - h).1, m.sample(t + h).1);
                let a = m.acceleration(t);
                for j in 0..ARM_JOINTS {
                    assert!(((v1[j] - v0[j]) / (2.0 * h) - a[j]).abs() < 1e-6, "t {t} joint {j}");
                }
            }
            assert_eq!(m.acceleration(-1.0), [0.0; 6]);
            assert_eq!(m.acceleration(tt + 1.0), [0.0; 6]);
        }
    }
}
