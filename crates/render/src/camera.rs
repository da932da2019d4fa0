//! Which camera draws the scene ([`Camera`]) and how the tracking camera follows the task
//! ([`Follow`]).

use std::fmt;

/// Name of the camera on the hand in `models/finger.xml` (the `hand` choice).
pub const HAND_CAMERA: &str = "hand";

/// Time constant of the tracking camera's follow \[s\]: a stated choice. The look-at point is a
/// critically damped second-order follower of the object ([`Follow`]), so a jitter of the held
/// object faster than about 1 / (2π · 0.1 s) ≈ 1.6 Hz is smoothed out, while the lag behind an
/// object carried at speed v is 2 τ v: 2.5 cm at the crimper's fastest in the paper's transfer
/// (0.12 m/s, from its run's `frames.bin`), well inside the default 0.35 m view (half its height
/// is 0.35 m · tan 22.5° ≈ 0.145 m).
pub const FOLLOW_TIME_S: f64 = 0.1;

/// The camera a picture is drawn with.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Camera {
    /// The free camera, its look-at point following the object (the hand when the scene has no
    /// object) through every phase ([`Follow`]) and its azimuth turning about the arm's base as
    /// the look-at point does; distance, elevation and the azimuth at the start as the view says.
    #[default]
    Tracking,
    /// The free camera aimed at the object in the first state drawn and left there.
    Fixed,
    /// The camera on the hand ([`HAND_CAMERA`]), looking along the tool past the finger.
    Hand,
    /// A camera of the scene's model, by name.
    Model(String),
}

impl Camera {
    /// The choices besides the model's own cameras, as `--camera` takes them.
    pub const CHOICES: [&'static str; 3] = ["tracking", "fixed", "hand"];

    /// The camera a `--camera` value names: one of [`Camera::CHOICES`], or else a model camera
    /// (checked against the model when the renderer is made).
    pub fn parse(name: &str) -> Camera {
        match name {
            "tracking" => Camera::Tracking,
            "fixed" => Camera::Fixed,
            "hand" => Camera::Hand,
            other => Camera::Model(other.to_string()),
        }
    }

    /// The name `parse` takes back.
    pub fn name(&self) -> &str {
        match self {
            Camera::Tracking => "tracking",
            Camera::Fixed => "fixed",
            Camera::Hand => "hand",
            Camera::Model(name) => name,
        }
    }

    /// Whether the picture is drawn by the free camera (tracking or fixed).
    pub fn is_free(&self) -> bool {
        matches!(self, Camera::Tracking | Camera::Fixed)
    }
}

impl fmt::Display for Camera {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A critically damped follower of a moving point: the point `x` obeys
/// ẍ = ω² (target − x) − 2 ω ẋ with ω = 1 / τ, integrated exactly between two calls with the
/// target held (so it is stable at any spacing of the calls, and never overshoots a step).
///
/// The first call, or one earlier in time than the last, jumps to the target.
#[derive(Debug, Clone, PartialEq)]
pub struct Follow {
    time_constant_s: f64,
    /// The point, its velocity and the time of the last call.
    state: Option<([f64; 3], [f64; 3], f64)>,
}

impl Follow {
    /// A follower with time constant `time_constant_s` \[s\] (> 0).
    pub fn new(time_constant_s: f64) -> Follow {
        Follow { time_constant_s, state: None }
    }

    /// Moves the point towards `target` for the time since the last call and returns it.
    pub fn update(&mut self, target: [f64; 3], time_s: f64) -> [f64; 3] {
        let (x, v) = match self.state {
            Some((x, v, t0)) if time_s >= t0 => {
                let w = 1.0 / self.time_constant_s;
                let dt = time_s - t0;
                let decay = (-w * dt).exp();
                let mut x1 = [0.0; 3];
                let mut v1 = [0.0; 3];
                for k in 0..3 {
                    let e = x[k] - target[k];
                    let c = v[k] + w * e;
                    x1[k] = target[k] + (e + c * dt) * decay;
                    v1[k] = (v[k] - w * c * dt) * decay;
                }
                (x1, v1)
            }
            _ => (target, [0.0; 3]),
        };
        self.state = Some((x, v, time_s));
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back() {
        for name in Camera::CHOICES.into_iter().chain(["top_view"]) {
            assert_eq!(Camera::parse(name).name(), name);
        }
        assert_eq!(Camera::parse("hand"), Camera::Hand);
        assert_eq!(Camera::parse("top_view"), Camera::Model("top_view".into()));
        assert_eq!(Camera::default(), Camera::Tracking);
        assert!(Camera::Fixed.is_free() && !Camera::Hand.is_free());
    }

    #[test]
    fn a_step_is_followed_without_overshoot() {
        let tau = 0.1;
        let mut f = Follow::new(tau);
        assert_eq!(f.update([0.0; 3], 0.0), [0.0; 3], "the first call jumps to the target");
        let mut last = 0.0;
        for k in 1..=60 {
            let x = f.update([1.0, 0.0, 0.0], k as f64 / 30.0)[0];
            assert!(x >= last && x <= 1.0, "monotone, no overshoot: {x} after {last}");
            last = x;
        }
        // Critically damped: 1 − (1 + t/τ) e^(−t/τ) at t = 2 s.
        assert!((last - 1.0).abs() < 1e-6, "{last}");
        let one_tau = Follow { state: Some(([0.0; 3], [0.0; 3], 0.0)), ..Follow::new(tau) }.update([1.0; 3], tau)[0];
        assert!((one_tau - (1.0 - 2.0 / std::f64::consts::E)).abs() < 1e-12, "{one_tau}");
    }

    #[test]
    fn a_steady_motion_is_followed_at_a_lag_of_two_time_constants() {
        let (tau, speed, dt) = (0.1, 0.2, 1.0 / 30.0);
        let mut f = Follow::new(tau);
        let mut lag = 0.0;
        for k in 0..=300 {
            let t = k as f64 * dt;
            lag = speed * t - f.update([speed * t, 0.0, 0.0], t)[0];
        }
        // 2 τ v behind a smooth motion; the target held at each call's value between calls runs
        // half a call's spacing ahead of the motion on average, which takes v dt / 2 off.
        assert!((lag - (2.0 * tau - dt / 2.0) * speed).abs() < 1e-6, "{lag}");
    }

    #[test]
    fn the_same_path_is_followed_at_any_frame_rate() {
        // Exact between calls: a target that moves in steps at 10 Hz is followed the same whether
        // the follower is called at 10 or 40 Hz (at the 10 Hz instants).
        let target = |t: f64| [(t * 10.0).floor().sin(), 0.0, 0.0];
        let (mut slow, mut fast) = (Follow::new(0.1), Follow::new(0.1));
        for k in 0..50 {
            let t = k as f64 / 10.0;
            let a = slow.update(target(t), t)[0];
            for j in 1..=4 {
                fast.update(target(t), t - 0.1 + 0.025 * f64::from(j));
            }
            let b = fast.update(target(t), t)[0];
            if k > 0 {
                assert!((a - b).abs() < 1e-9, "{k}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn going_back_in_time_jumps_to_the_target() {
        let mut f = Follow::new(0.1);
        f.update([0.0; 3], 5.0);
        assert_eq!(f.update([1.0; 3], 1.0), [1.0; 3]);
    }
}
