//! The virtual controller's motion generator: the joint setpoint it commands every control cycle
//! for `movej`, `movel`, `servoj`, `speedj` and `stopj`/`stopl`.
//!
//! - `movej(q, a, v, t)`: a trapezoidal speed profile in joint space; every joint starts and stops
//!   together, the one with the farthest to go at speed `v` (rad/s) and acceleration `a` (rad/s²)
//!   (`t` > 0 scales it in time to last exactly `t`, `a` and `v` then ignored, as the manual
//!   says). UR's controller also uses such a synchronised
//!   trapezoid; its exact blend of jerk limits is not modelled.
//! - `movel(pose, a, v, t)`: the same profile over the straight path of the TCP (m/s, m/s²): the
//!   position interpolated linearly, the orientation along the shortest rotation; each cycle's
//!   pose turned into joints by [`ur5e::inverse_near`] from the previous setpoint (so the arm stays
//!   on its branch). A pose it cannot reach is an error. `movep` is the same move (its blends,
//!   which keep the tool speed constant through waypoints, are not modelled, so one `movep` is a
//!   `movel` with the same profile).
//! - `movec(via, to, a, v, mode)`: the same profile along the circle through the TCP, `via` and
//!   `to`; the orientation goes from the start's to `to`'s along the shortest rotation (mode 0,
//!   unconstrained), or turns with the circle's tangent (mode 1, fixed).
//! - `speedl(xd, a, t)`: the TCP twist ramped towards `xd` at `a` (m/s², rad/s² for the rotation),
//!   integrated every cycle into a TCP pose whose joints come from [`ur5e::inverse_near`]; as
//!   `speedj`, it decelerates once not renewed.
//!
//! Poses are the TCP's: the program's TCP offset (`set_tcp`, [`Arm::set_tcp`]) lies between the
//! flange the kinematics give and the pose a program names.
//! - `servoj(q, t=...)`: the target itself. The arm is commanded when the target changes or an RTDE
//!   input package arrived since the last command: the twin's kinematic arm spreads a move over the
//!   time since the command before, so a target streamed over RTDE is followed at the client's
//!   cadence, the smoothing `servoj`'s lookahead gives on the real controller. Re-commanding an
//!   unchanged target every 2 ms instead would make the arm jump to each new target within one
//!   physics step and stand still until the next (the hand shook at the control rate, see
//!   `docs/cell/urscript.md`).
//! - `speedj(qd, a, t)`: joint speeds ramped towards `qd` at `a`; when the call that set them has
//!   returned and no new `speedj` follows within a cycle, the arm decelerates at `a`.
//! - `stopj(a)`: every joint decelerates at `a`, scaled so they stop together. After `servoj` the
//!   setpoint has no speed (the twin's servo model has none), so the arm holds the last target.
//!   `stopl(a)` does the same with `a` over a 0.5 m lever (m/s² to rad/s²; an approximation).
//!
//! Speeds are capped at the UR5e's joint speed (π rad/s), the protective-stop limit.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use tendril_ur5e::kinematics as ur5e;
use tendril_ur5e::pose::{pose_from_vector, pose_vector};
use tendril_ur5e::safety::MAX_JOINT_SPEED_RAD_S;

/// Deceleration when a moving thread is killed, or the arm is put in freedrive \[rad/s²\].
pub const KILL_DECEL_RAD_S2: f64 = 4.0;
/// Lever that turns a tool acceleration into a joint one for `stopl` \[m\].
pub const STOPL_LEVER_M: f64 = 0.5;

/// A trapezoidal (or triangular, if too short to reach `v`) profile over a distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    dist: f64,
    v: f64,
    a: f64,
    t_acc: f64,
    total: f64,
    /// Time stretch factor (≥ 1) for a requested duration.
    stretch: f64,
}

impl Profile {
    /// The profile over `dist` (≥ 0) at top speed `v` and acceleration `a` (both > 0); a time
    /// `t` \[s\] > 0 makes it last exactly that long, its shape scaled in time (URScript's `t`:
    /// "the speed and acceleration are then ignored").
    pub fn new(dist: f64, v: f64, a: f64, t: f64) -> Profile {
        let (v, a) = (v.max(1e-9), a.max(1e-9));
        let (t_acc, total, v) = if dist * a < v * v {
            let t = (dist / a).sqrt();
            (t, 2.0 * t, a * t)
        } else {
            (v / a, dist / v + v / a, v)
        };
        let stretch = if t > 0.0 && total > 0.0 { t / total } else { 1.0 };
        Profile { dist, v, a, t_acc, total, stretch }
    }

    /// Duration \[s\].
    pub fn duration(&self) -> f64 {
        self.total * self.stretch
    }

    /// Fraction of the distance covered at time `t` after the start, in \[0, 1\].
    pub fn fraction(&self, t: f64) -> f64 {
        if self.dist <= 0.0 || self.total <= 0.0 || !self.total.is_finite() {
            return 1.0;
        }
        let t = (t / self.stretch).clamp(0.0, self.total);
        let s = if t < self.t_acc {
            0.5 * self.a * t * t
        } else if t <= self.total - self.t_acc {
            0.5 * self.a * self.t_acc * self.t_acc + self.v * (t - self.t_acc)
        } else {
            let r = self.total - t;
            self.dist - 0.5 * self.a * r * r
        };
        (s / self.dist).clamp(0.0, 1.0)
    }
}

/// The TCP's path for a Cartesian move.
#[derive(Debug, Clone, PartialEq)]
enum Path {
    /// A straight line, the orientation along the shortest rotation.
    Line { from: Isometry3<f64>, to: Isometry3<f64> },
    /// An arc of `angle` about `axis` through `centre`, starting at `from`; the orientation goes to
    /// `to_rotation`, or (fixed mode, `None`) turns with the arc.
    Arc {
        from: Isometry3<f64>,
        centre: Vector3<f64>,
        axis: nalgebra::Unit<Vector3<f64>>,
        angle: f64,
        to_rotation: Option<UnitQuaternion<f64>>,
    },
}

impl Path {
    /// The TCP pose a fraction `f` of the way along.
    fn at(&self, f: f64) -> Isometry3<f64> {
        match self {
            Path::Line { from, to } => {
                let p = from.translation.vector.lerp(&to.translation.vector, f);
                Isometry3::from_parts(Translation3::from(p), from.rotation.slerp(&to.rotation, f))
            }
            Path::Arc { from, centre, axis, angle, to_rotation } => {
                let turn = UnitQuaternion::from_axis_angle(axis, angle * f);
                let p = centre + turn * (from.translation.vector - centre);
                let r = match to_rotation {
                    Some(to) => from.rotation.slerp(to, f),
                    None => turn * from.rotation,
                };
                Isometry3::from_parts(Translation3::from(p), r)
            }
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Motion {
    Hold,
    Joint {
        from: [f64; 6],
        to: [f64; 6],
        profile: Profile,
        start: f64,
    },
    Cartesian {
        path: Path,
        profile: Profile,
        start: f64,
    },
    Servo,
    Speed {
        target: [f64; 6],
        accel: f64,
        until: f64,
    },
    /// `speedl`: the TCP twist now, the one aimed at, the accelerations (linear, rotational).
    SpeedL {
        twist: [f64; 6],
        target: [f64; 6],
        accel: (f64, f64),
        until: f64,
    },
    Stop {
        decel: f64,
    },
}

/// The commanded arm: setpoint, its speed, and the motion producing it.
#[derive(Debug, Clone, PartialEq)]
pub struct Arm {
    q: [f64; 6],
    qd: [f64; 6],
    motion: Motion,
    /// Number of the current motion (each new motion command gets the next).
    id: u64,
    done: bool,
    /// The thread that commanded it.
    owner: Option<u64>,
    /// The last servo target commanded and the RTDE input package count then.
    servo_sent: Option<([f64; 6], u64)>,
    /// A setpoint to command this cycle.
    pending: Option<[f64; 6]>,
    /// The TCP offset from the flange (`set_tcp`).
    tcp: Isometry3<f64>,
}

fn norm(v: &[f64; 6]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn max_abs(v: &[f64; 6]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

impl Arm {
    /// An arm at rest at `q` \[rad\].
    pub fn new(q: [f64; 6]) -> Arm {
        Arm {
            q,
            qd: [0.0; 6],
            motion: Motion::Hold,
            id: 0,
            done: true,
            owner: None,
            servo_sent: None,
            pending: None,
            tcp: Isometry3::identity(),
        }
    }

    /// Sets the TCP offset from the flange (`[x, y, z, rx, ry, rz]`, m and rad).
    pub fn set_tcp(&mut self, offset: &[f64; 6]) {
        self.tcp = pose_from_vector(offset);
    }

    /// The TCP pose at joint angles `q`.
    pub fn tcp_at(&self, q: &[f64; 6]) -> Isometry3<f64> {
        ur5e::forward(q) * self.tcp
    }

    /// Joint angles near `near` that put the TCP at `pose`, if the arm reaches it.
    pub fn joints_for(&self, pose: &Isometry3<f64>, near: &[f64; 6]) -> Option<[f64; 6]> {
        ur5e::inverse_near(&(pose * self.tcp.inverse()), near)
    }

    /// The setpoint \[rad\] (`get_target_joint_positions`).
    pub fn target_q(&self) -> [f64; 6] {
        self.q
    }

    /// The setpoint's speed \[rad/s\] (`get_target_joint_speeds`).
    pub fn target_qd(&self) -> [f64; 6] {
        self.qd
    }

    /// Whether the arm follows `servoj` targets (each commanded as it arrives) rather than a
    /// generated trajectory.
    pub fn servoing(&self) -> bool {
        self.motion == Motion::Servo
    }

    /// Whether motion `id` is over (finished, or replaced by another).
    pub fn finished(&self, id: u64) -> bool {
        id != self.id || self.done
    }

    /// The thread whose motion is running, if one is.
    pub fn owner(&self) -> Option<u64> {
        if self.done { None } else { self.owner }
    }

    fn begin(&mut self, motion: Motion, owner: u64) -> u64 {
        self.motion = motion;
        self.id += 1;
        self.done = false;
        self.owner = Some(owner);
        self.id
    }

    /// `movej`: returns the motion's number (the caller waits until it is finished).
    pub fn movej(&mut self, to: [f64; 6], a: f64, v: f64, t: f64, owner: u64) -> u64 {
        if to.iter().any(|x| !x.is_finite()) {
            // Commanded as it is: the safety check turns it into a protective stop.
            self.pending = Some(to);
            let id = self.begin(Motion::Hold, owner);
            self.done = true;
            return id;
        }
        let dist = (0..6).fold(0.0_f64, |m, j| m.max((to[j] - self.q[j]).abs()));
        let profile = Profile::new(dist, v.min(MAX_JOINT_SPEED_RAD_S), a, t);
        self.begin(Motion::Joint { from: self.q, to, profile, start: f64::NAN }, owner)
    }

    /// `movel` (and `movep`) to a TCP pose; an error if the pose is not a finite pose.
    pub fn movel(&mut self, to: [f64; 6], a: f64, v: f64, t: f64, owner: u64) -> Result<u64, String> {
        if to.iter().any(|x| !x.is_finite()) {
            return Err(format!("movel target {to:?} is not finite"));
        }
        let from = self.tcp_at(&self.q);
        let to = pose_from_vector(&to);
        let dist = (to.translation.vector - from.translation.vector).norm();
        // A pure rotation moves along its angle instead (rad at the same numbers).
        let dist = if dist > 1e-6 { dist } else { from.rotation.angle_to(&to.rotation) };
        let profile = Profile::new(dist, v, a, t);
        Ok(self.begin(Motion::Cartesian { path: Path::Line { from, to }, profile, start: f64::NAN }, owner))
    }

    /// `movec` through TCP pose `via` to TCP pose `to`; `fixed` keeps the orientation turning with
    /// the arc (mode 1). An error if the three points are (nearly) on one line.
    pub fn movec(
        &mut self,
        via: [f64; 6],
        to: [f64; 6],
        a: f64,
        v: f64,
        fixed: bool,
        owner: u64,
    ) -> Result<u64, String> {
        if via.iter().chain(&to).any(|x| !x.is_finite()) {
            return Err(format!("movec points {via:?}, {to:?} are not finite"));
        }
        let from = self.tcp_at(&self.q);
        let (p0, to) = (from.translation.vector, pose_from_vector(&to));
        let (p1, p2) = (Vector3::new(via[0], via[1], via[2]), to.translation.vector);
        // The circle through three points: centre where the perpendicular bisectors meet.
        let (u, w) = (p1 - p0, p2 - p0);
        let n = u.cross(&w);
        if n.norm() < 1e-9 {
            return Err("movec: the start, via and end points are on one line".into());
        }
        let centre = p0 + (w.norm_squared() * n.cross(&u) + u.norm_squared() * w.cross(&n)) / (2.0 * n.norm_squared());
        let axis = nalgebra::Unit::new_normalize(n);
        let angle_to = |p: Vector3<f64>| {
            let (a, b) = (p0 - centre, p - centre);
            let ang = a.cross(&b).dot(&axis).atan2(a.dot(&b));
            if ang < 0.0 { ang + std::f64::consts::TAU } else { ang }
        };
        // n = u × w points so that going from p0 towards p1 then p2 is positive about it.
        let angle = angle_to(p2);
        let radius = (p0 - centre).norm();
        let to_rotation = (!fixed).then_some(to.rotation);
        let profile = Profile::new(radius * angle, v, a, 0.0);
        let path = Path::Arc { from, centre, axis, angle, to_rotation };
        Ok(self.begin(Motion::Cartesian { path, profile, start: f64::NAN }, owner))
    }

    /// `speedl` towards TCP twist `xd` (m/s, rad/s) at accelerations `a` (m/s²) and `a_rot`
    /// (rad/s²), the call returning at `until` \[s\].
    pub fn speedl(&mut self, xd: [f64; 6], a: f64, a_rot: f64, until: f64, owner: u64) -> u64 {
        match &mut self.motion {
            Motion::SpeedL { target, accel, until: u, .. } if !self.done => {
                (*target, *accel, *u) = (xd, (a, a_rot), until);
                self.owner = Some(owner);
                self.id
            }
            _ => self.begin(Motion::SpeedL { twist: [0.0; 6], target: xd, accel: (a, a_rot), until }, owner),
        }
    }

    /// `servoj` to `q`; `packages` counts the RTDE input packages so far.
    pub fn servoj(&mut self, q: [f64; 6], packages: u64, owner: u64) -> u64 {
        if self.motion != Motion::Servo || self.done {
            self.begin(Motion::Servo, owner);
        }
        if self.servo_sent != Some((q, packages)) {
            self.servo_sent = Some((q, packages));
            self.pending = Some(q);
        }
        self.q = q;
        self.qd = [0.0; 6];
        self.id
    }

    /// `speedj` towards `qd` at `accel`, the call returning at `until` \[s\].
    pub fn speedj(&mut self, qd: [f64; 6], accel: f64, until: f64, owner: u64) -> u64 {
        let target = qd.map(|v| v.clamp(-MAX_JOINT_SPEED_RAD_S, MAX_JOINT_SPEED_RAD_S));
        match &mut self.motion {
            Motion::Speed { target: t, accel: a, until: u } if !self.done => {
                (*t, *a, *u) = (target, accel, until);
                self.owner = Some(owner);
                self.id
            }
            _ => self.begin(Motion::Speed { target, accel, until }, owner),
        }
    }

    /// `stopj(decel)`: the motion's number (finished at once if the setpoint is still).
    pub fn stopj(&mut self, decel: f64, owner: u64) -> u64 {
        let id = self.begin(Motion::Stop { decel: decel.max(1e-3) }, owner);
        if max_abs(&self.qd) == 0.0 {
            self.motion = Motion::Hold;
            self.done = true;
        }
        id
    }

    /// A killed thread's motion: the arm stops at `decel`.
    pub fn abandon(&mut self, thread: u64, decel: f64) {
        if self.owner() == Some(thread) && !matches!(self.motion, Motion::Stop { .. }) {
            self.stopj(decel, thread);
        }
    }

    /// Advances the setpoint to time `now` (cycle length `dt`) and returns the setpoint to command
    /// this cycle, if any.
    pub fn tick(&mut self, now: f64, dt: f64) -> Result<Option<[f64; 6]>, String> {
        let (before, speed_before) = (self.q, self.qd);
        let mut moved = false;
        // Joint and linear moves: the speed is the setpoint's change over the cycle.
        let kinematic = matches!(self.motion, Motion::Joint { .. } | Motion::Cartesian { .. } | Motion::SpeedL { .. });
        match &mut self.motion {
            Motion::Hold | Motion::Servo => {}
            Motion::Joint { from, to, profile, start } => {
                if start.is_nan() {
                    *start = now - dt;
                }
                let t = now - *start;
                let f = profile.fraction(t);
                self.q = std::array::from_fn(|j| from[j] + (to[j] - from[j]) * f);
                moved = true;
                if t >= profile.duration() {
                    self.q = *to;
                    self.done = true;
                }
            }
            Motion::Cartesian { path, profile, start } => {
                if start.is_nan() {
                    *start = now - dt;
                }
                let t = now - *start;
                let pose = path.at(profile.fraction(t));
                let finished = t >= profile.duration();
                self.q = ur5e::inverse_near(&(pose * self.tcp.inverse()), &self.q)
                    .ok_or_else(|| format!("no joint solution near the arm for the TCP at {:?}", pose_vector(&pose)))?;
                moved = true;
                if finished {
                    self.done = true;
                }
            }
            Motion::SpeedL { twist, target, accel, until } => {
                if now > *until + 0.5 * dt {
                    *target = [0.0; 6];
                }
                let before_twist = *twist;
                // Linear and rotational parts each ramp at their acceleration.
                for (range, a) in [(0..3, accel.0), (3..6, accel.1)] {
                    let dv: Vec<f64> = range.clone().map(|k| target[k] - twist[k]).collect();
                    let size = dv.iter().map(|x| x * x).sum::<f64>().sqrt();
                    let scale = if size > 0.0 { (a * dt / size).min(1.0) } else { 0.0 };
                    for (k, d) in range.zip(dv) {
                        twist[k] += d * scale;
                    }
                }
                // As speedj: the twist ramps within the cycle, the way is its mean times the cycle.
                let mean: [f64; 6] = std::array::from_fn(|k| 0.5 * (before_twist[k] + twist[k]));
                let pose = ur5e::forward(&self.q) * self.tcp;
                let p = pose.translation.vector + Vector3::new(mean[0], mean[1], mean[2]) * dt;
                let r = UnitQuaternion::from_scaled_axis(Vector3::new(mean[3], mean[4], mean[5]) * dt) * pose.rotation;
                let next = Isometry3::from_parts(Translation3::from(p), r);
                self.q = ur5e::inverse_near(&(next * self.tcp.inverse()), &self.q).ok_or_else(|| {
                    format!("speedl: no joint solution near the arm for the TCP at {:?}", pose_vector(&next))
                })?;
                moved = true;
                if now > *until + 0.5 * dt && twist.iter().all(|v| *v == 0.0) {
                    self.done = true;
                }
            }
            Motion::Speed { target, accel, until } => {
                if now > *until + 0.5 * dt {
                    let decel = *accel;
                    self.motion = Motion::Stop { decel };
                    return self.tick(now, dt);
                }
                let dv: [f64; 6] = std::array::from_fn(|j| target[j] - self.qd[j]);
                let scale = (*accel * dt / max_abs(&dv).max(1e-12)).min(1.0);
                let old = self.qd;
                self.qd = std::array::from_fn(|j| old[j] + dv[j] * scale);
                // The speed ramps linearly within the cycle: the way is its mean times the cycle
                // (a spline run as speedj steps, as UR's external control program runs them, then
                // lands on its points).
                self.q = std::array::from_fn(|j| self.q[j] + 0.5 * (old[j] + self.qd[j]) * dt);
                moved = true;
            }
            Motion::Stop { decel } => {
                let speed = max_abs(&self.qd);
                let scale = if speed > 0.0 { ((speed - *decel * dt).max(0.0)) / speed } else { 0.0 };
                let old = self.qd;
                self.qd = old.map(|v| v * scale);
                // Trapezoidal integration: the speed falls linearly within the cycle.
                self.q = std::array::from_fn(|j| self.q[j] + 0.5 * (old[j] + self.qd[j]) * dt);
                moved = norm(&old) > 0.0;
                if scale == 0.0 {
                    self.motion = Motion::Hold;
                    self.done = true;
                }
            }
        }
        if kinematic {
            self.qd = std::array::from_fn(|j| (self.q[j] - before[j]) / dt);
            if self.done {
                // On the target: at rest (the profile ends at zero speed).
                self.qd = [0.0; 6];
                self.motion = Motion::Hold;
            }
        }
        if let Some(q) = self.pending.take() {
            return Ok(Some(q));
        }
        // A new setpoint, or the same one with a new speed (the motion just came to rest: the
        // twin extrapolates a moving setpoint, so it must learn that it stopped).
        Ok(if (moved && self.q != before) || self.qd != speed_before { Some(self.q) } else { None })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.002;

    fn run(arm: &mut Arm, from: f64, seconds: f64) -> Vec<[f64; 6]> {
        let n = (seconds / DT).round() as usize;
        (1..=n).filter_map(|k| arm.tick(from + k as f64 * DT, DT).unwrap()).collect()
    }

    #[test]
    fn a_trapezoid_reaches_its_distance_at_its_duration() {
        let p = Profile::new(1.0, 0.5, 1.0, 0.0);
        assert!((p.duration() - 2.5).abs() < 1e-12);
        assert_eq!(p.fraction(0.0), 0.0);
        assert!((p.fraction(1.25) - 0.5).abs() < 1e-12);
        assert_eq!(p.fraction(2.5), 1.0);
        let short = Profile::new(0.01, 1.0, 1.0, 0.0);
        assert!((short.duration() - 0.2).abs() < 1e-12, "triangular");
        assert!((Profile::new(1.0, 0.5, 1.0, 5.0).duration() - 5.0).abs() < 1e-12, "stretched to t");
        let fast = Profile::new(1.0, 0.5, 1.0, 1.0);
        assert!((fast.duration() - 1.0).abs() < 1e-12, "compressed to t: a and v ignored");
        assert!((fast.fraction(0.5) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn movej_moves_all_joints_together_and_finishes_on_the_target() {
        let mut arm = Arm::new([0.0; 6]);
        let to = [0.2, -0.1, 0.0, 0.0, 0.05, 0.0];
        let id = arm.movej(to, 1.4, 1.05, 0.0, 1);
        let path = run(&mut arm, 0.0, 1.0);
        assert!(arm.finished(id));
        assert_eq!(arm.target_q(), to);
        // Joint 1 is always half of joint 0's way along (synchronised).
        for q in &path {
            assert!((q[1] + 0.5 * q[0]).abs() < 1e-12, "{q:?}");
        }
        // Never faster than v.
        for w in path.windows(2) {
            assert!((w[1][0] - w[0][0]).abs() / DT <= 1.05 + 1e-9);
        }
    }

    #[test]
    fn speedj_ramps_then_stops_when_not_renewed_and_stopj_decelerates() {
        let mut arm = Arm::new([0.0; 6]);
        arm.speedj([0.5, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0, 0.6, 1);
        run(&mut arm, 0.0, 0.6);
        assert!((arm.target_qd()[0] - 0.5).abs() < 1e-9, "at speed after 0.5 s of ramp");
        // Not renewed: it stops at 1 rad/s² within 0.5 s.
        run(&mut arm, 0.6, 0.6);
        assert_eq!(arm.target_qd(), [0.0; 6]);
        let stopped = arm.target_q()[0];
        assert!(stopped > 0.3 && stopped < 0.45, "{stopped}");
        let id = arm.stopj(2.0, 1);
        assert!(arm.finished(id), "already still");
    }

    #[test]
    fn servoj_commands_only_new_targets_or_new_packages() {
        let mut arm = Arm::new([0.0; 6]);
        let q = [0.01; 6];
        arm.servoj(q, 5, 1);
        assert_eq!(arm.tick(DT, DT).unwrap(), Some(q));
        arm.servoj(q, 5, 1);
        assert_eq!(arm.tick(2.0 * DT, DT).unwrap(), None, "same target, no new package");
        arm.servoj(q, 6, 1);
        assert_eq!(arm.tick(3.0 * DT, DT).unwrap(), Some(q), "a new package re-commands");
        let id = arm.stopj(2.0, 1);
        assert!(arm.finished(id), "servo has no speed: the arm holds the target");
        assert_eq!(arm.tick(4.0 * DT, DT).unwrap(), None);
    }

    #[test]
    fn movel_goes_straight() {
        let q0 = ur5e::HOME;
        let mut arm = Arm::new(q0);
        let start = pose_vector(&ur5e::forward(&q0));
        let mut goal = start;
        goal[2] -= 0.05;
        let id = arm.movel(goal, 1.2, 0.25, 0.0, 1).unwrap();
        let path = run(&mut arm, 0.0, 1.0);
        assert!(arm.finished(id));
        for q in &path {
            let p = ur5e::forward(q).translation.vector;
            assert!((p.x - start[0]).abs() < 2e-4 && (p.y - start[1]).abs() < 2e-4, "{p}");
        }
        let end = ur5e::forward(&arm.target_q()).translation.vector;
        assert!((end.z - goal[2]).abs() < 2e-4);
        assert!(arm.movel([f64::NAN; 6], 1.0, 1.0, 0.0, 1).is_err());
    }
}
