//! UR5e kinematics from UR's DH table (docs/facts.md#ur5e-dh-table): forward kinematics to the tool flange and a
//! damped-least-squares inverse near a seed, for the kinematic arm mode, for planning poses and for
//! the slip detector's hand height (`tendril_control::slip`).

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3, Vector6};

/// DH d \[m\] (Universal Robots, "DH Parameters for calculations of kinematics and dynamics").
pub const D: [f64; 6] = [0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996];
/// DH a \[m\].
pub const A: [f64; 6] = [0.0, -0.425, -0.3922, 0.0, 0.0, 0.0];
/// DH alpha \[rad\].
pub const ALPHA: [f64; 6] =
    [std::f64::consts::FRAC_PI_2, 0.0, 0.0, std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2, 0.0];
/// A commonly used home pose \[rad\] (docs/facts.md#ur5e-home-pose): tool flange pointing down.
pub const HOME: [f64; 6] = [
    -std::f64::consts::FRAC_PI_2,
    -std::f64::consts::FRAC_PI_2,
    std::f64::consts::FRAC_PI_2,
    -std::f64::consts::FRAC_PI_2,
    -std::f64::consts::FRAC_PI_2,
    0.0,
];

/// Pose of the tool flange in the base frame for joint angles `q` \[rad\]:
/// the product of Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i).
pub fn forward(q: &[f64; 6]) -> Isometry3<f64> {
    let mut t = Isometry3::identity();
    for i in 0..6 {
        let rz =
            Isometry3::from_parts(Translation3::identity(), UnitQuaternion::from_axis_angle(&Vector3::z_axis(), q[i]));
        let tr = Isometry3::from_parts(
            Translation3::new(A[i], 0.0, D[i]),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), ALPHA[i]),
        );
        t = t * rz * tr;
    }
    t
}

/// Joint angles that put the flange at `target`, found by damped least squares starting from `seed`
/// (so the solution stays on the seed's branch). `None` when 200 iterations do not reach 0.1 mm and
/// 1 mrad (target out of reach or singular).
///
/// The iterations go on to 1 nm and 1 nrad when they can, so that a target moved by less than the
/// acceptance bound still moves the solution: a setpoint solved every control cycle along a path
/// (`movel`, `speedl`) would otherwise stand still for cycles and then jump.
pub fn inverse_near(target: &Isometry3<f64>, seed: &[f64; 6]) -> Option<[f64; 6]> {
    let within =
        |e: &Vector6<f64>, m: f64, rad: f64| e.fixed_rows::<3>(0).norm() < m && e.fixed_rows::<3>(3).norm() < rad;
    let mut q = *seed;
    for _ in 0..200 {
        let e = pose_error(target, &forward(&q));
        if within(&e, 1e-9, 1e-9) {
            return Some(q);
        }
        // Numerical Jacobian: six forward kinematics, cheap next to a physics step.
        let mut j = nalgebra::Matrix6::zeros();
        let h = 1e-7;
        for k in 0..6 {
            let mut qk = q;
            qk[k] += h;
            let de = pose_error(&forward(&qk), &forward(&q));
            j.set_column(k, &(de / h));
        }
        let lambda2 = 1e-4;
        let jjt = j * j.transpose() + nalgebra::Matrix6::identity() * lambda2;
        let dq = j.transpose() * jjt.lu().solve(&e)?;
        for k in 0..6 {
            q[k] += dq[k].clamp(-0.2, 0.2);
        }
    }
    within(&pose_error(target, &forward(&q)), 1e-4, 1e-3).then_some(q)
}

/// Twist-like error from `from` to `to`: position difference and rotation vector, both in the base frame.
fn pose_error(to: &Isometry3<f64>, from: &Isometry3<f64>) -> Vector6<f64> {
    let dp = to.translation.vector - from.translation.vector;
    let dr = (to.rotation * from.rotation.inverse()).scaled_axis();
    Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_pose_matches_the_dh_reach() {
        // All joints at zero: the arm lies stretched along -x, flange at (a2 + a3, -d4 - d6... ) per UR.
        let p = forward(&[0.0; 6]).translation.vector;
        assert!((p.x - (A[1] + A[2])).abs() < 1e-12, "{p}");
        assert!((p.y - (-(D[3] + D[5]))).abs() < 1e-12, "{p}");
        assert!((p.z - (D[0] - D[4])).abs() < 1e-12, "{p}");
    }

    #[test]
    fn inverse_recovers_a_pose() {
        let q = [-1.4, -1.7, 1.9, -1.8, -1.57, 0.3];
        let target = forward(&q);
        let found = inverse_near(&target, &HOME).expect("reachable");
        let got = forward(&found);
        assert!((got.translation.vector - target.translation.vector).norm() < 1e-4);
        assert!(got.rotation.angle_to(&target.rotation) < 1e-3);
    }
}
