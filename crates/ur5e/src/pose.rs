//! The virtual UR5e's TCP pose as RTDE reports it: `[x, y, z, rx, ry, rz]` in the robot's base
//! frame, metres and an axis-angle rotation vector (radians).
//!
//! Frames: [`ur5e::forward`] is the product of UR's DH transforms, so it starts in DH frame 0 and
//! ends in DH frame 6. UR's controller reports poses in its "Base" frame, which is DH frame 0 (z up
//! along the base axis; the ROS `base_link` is this frame turned by 180° about z, the ROS `base`
//! frame is this one), and its TCP with a zero `tcp_offset` is the tool flange, DH frame 6 (ROS
//! `tool0`). No offset is needed between them: at all joints zero the flange is at
//! (a2 + a3, −d4 − d6, d1 − d5), as on the pendant.

use crate::kinematics as ur5e;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// `[x, y, z, rx, ry, rz]` of a pose: translation \[m\] and rotation vector \[rad\] (angle in [0, π]).
pub fn pose_vector(pose: &Isometry3<f64>) -> [f64; 6] {
    let t = pose.translation.vector;
    let r = pose.rotation.scaled_axis();
    [t.x, t.y, t.z, r.x, r.y, r.z]
}

/// The pose a `[x, y, z, rx, ry, rz]` vector describes.
pub fn pose_from_vector(v: &[f64; 6]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_scaled_axis(Vector3::new(v[3], v[4], v[5])),
    )
}

/// The TCP pose for joint angles `q` \[rad\] and a TCP offset from the flange (`tcp_offset`, as
/// RTDE reports it), as `actual_TCP_pose` / `target_TCP_pose` give it.
pub fn tcp_pose(q: &[f64; 6], tcp_offset: &[f64; 6]) -> [f64; 6] {
    pose_vector(&(ur5e::forward(q) * pose_from_vector(tcp_offset)))
}

/// The TCP's twist for joint angles `q` \[rad\] moving at `qd` \[rad/s\] with a TCP offset:
/// `[vx, vy, vz, wx, wy, wz]` in the base frame (m/s, rad/s), as `actual_TCP_speed` gives it.
/// The forward kinematics differenced over a 1 µs step along `qd` (its error is that step times the
/// twist's rate of change, far below the digits RTDE clients read).
pub fn tcp_speed(q: &[f64; 6], qd: &[f64; 6], tcp_offset: &[f64; 6]) -> [f64; 6] {
    const H: f64 = 1e-6;
    let offset = pose_from_vector(tcp_offset);
    let a = ur5e::forward(q) * offset;
    let b = ur5e::forward(&std::array::from_fn(|j| q[j] + qd[j] * H)) * offset;
    let v = (b.translation.vector - a.translation.vector) / H;
    let w = (b.rotation * a.rotation.inverse()).scaled_axis() / H;
    [v.x, v.y, v.z, w.x, w.y, w.z]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// UR's DH table (d1, a2, a3, d4, d5, d6) for the hand-derived poses.
    const D1: f64 = 0.1625;
    const A2: f64 = -0.425;
    const A3: f64 = -0.3922;
    const D4: f64 = 0.1333;
    const D5: f64 = 0.0997;
    const D6: f64 = 0.0996;

    /// Standard DH product with explicit 4×4 matrices, written independently of `ur5e::forward`.
    fn dh_matrix(q: &[f64; 6]) -> [[f64; 4]; 4] {
        let d = [D1, 0.0, 0.0, D4, D5, D6];
        let a = [0.0, A2, A3, 0.0, 0.0, 0.0];
        let alpha = [PI / 2.0, 0.0, 0.0, PI / 2.0, -PI / 2.0, 0.0];
        let mut t = [[0.0; 4]; 4];
        (0..4).for_each(|i| t[i][i] = 1.0);
        for i in 0..6 {
            let (s, c) = q[i].sin_cos();
            let (sa, ca) = alpha[i].sin_cos();
            let m = [
                [c, -s * ca, s * sa, a[i] * c],
                [s, c * ca, -c * sa, a[i] * s],
                [0.0, sa, ca, d[i]],
                [0.0, 0.0, 0.0, 1.0],
            ];
            let mut n = [[0.0; 4]; 4];
            for r in 0..4 {
                for k in 0..4 {
                    n[r][k] = (0..4).map(|j| t[r][j] * m[j][k]).sum();
                }
            }
            t = n;
        }
        t
    }

    #[test]
    fn home_pose_is_the_flange_derived_from_the_dh_table() {
        // Home [-90, -90, 90, -90, -90, 0]°: upper arm up, forearm along +y, flange pointing down.
        let q = [-PI / 2.0, -PI / 2.0, PI / 2.0, -PI / 2.0, -PI / 2.0, 0.0];
        let p = tcp_pose(&q, &[0.0; 6]);
        let expected = [-D4, -A3 + D5, D1 - A2 - D6];
        for k in 0..3 {
            assert!((p[k] - expected[k]).abs() < 1e-9, "{p:?} vs {expected:?}");
        }
        // (-0.1333, 0.4919, 0.4879) m; rotation: π about x (x stays, y and z flip).
        assert!((p[0] + 0.1333).abs() < 1e-9 && (p[1] - 0.4919).abs() < 1e-9 && (p[2] - 0.4879).abs() < 1e-9);
        assert!((p[3].abs() - PI).abs() < 1e-6 && p[4].abs() < 1e-6 && p[5].abs() < 1e-6, "{p:?}");
    }

    #[test]
    fn poses_match_an_independent_dh_product_and_round_trip() {
        for q in [[0.0; 6], [0.3, -1.2, 1.9, -2.2, -1.4, 0.7], [-2.5, -0.4, -1.0, 0.9, 2.0, -3.0]] {
            let m = dh_matrix(&q);
            let p = tcp_pose(&q, &[0.0; 6]);
            let pose = pose_from_vector(&p);
            let r = pose.rotation.to_rotation_matrix();
            for i in 0..3 {
                assert!((p[i] - m[i][3]).abs() < 1e-9, "{q:?}: {p:?}");
                for j in 0..3 {
                    assert!((r[(i, j)] - m[i][j]).abs() < 1e-9, "{q:?}: rotation {r} vs {m:?}");
                }
            }
            assert!(p[3..].iter().map(|v| v * v).sum::<f64>().sqrt() <= PI + 1e-12);
        }
        let zero = tcp_pose(&[0.0; 6], &[0.0; 6]);
        assert!((zero[0] - (A2 + A3)).abs() < 1e-12 && (zero[1] + D4 + D6).abs() < 1e-12);
        assert!((zero[2] - (D1 - D5)).abs() < 1e-12);
    }

    #[test]
    fn the_tcp_speed_of_a_base_rotation_is_omega_cross_r() {
        // Joint 0 turns the whole arm about the base's z axis: v = ω × r, ω = (0, 0, w).
        let q = [-PI / 2.0, -PI / 2.0, PI / 2.0, -PI / 2.0, -PI / 2.0, 0.0];
        let w = 0.3;
        let p = tcp_pose(&q, &[0.0; 6]);
        let s = tcp_speed(&q, &[w, 0.0, 0.0, 0.0, 0.0, 0.0], &[0.0; 6]);
        let expected = [-w * p[1], w * p[0], 0.0, 0.0, 0.0, w];
        for k in 0..6 {
            assert!((s[k] - expected[k]).abs() < 1e-5, "{s:?} vs {expected:?}");
        }
        assert_eq!(tcp_speed(&q, &[0.0; 6], &[0.0; 6]), [0.0; 6]);
    }

    #[test]
    fn a_tcp_offset_moves_the_tcp_along_the_flange_axes() {
        let q = [-PI / 2.0, -PI / 2.0, PI / 2.0, -PI / 2.0, -PI / 2.0, 0.0];
        let flange = tcp_pose(&q, &[0.0; 6]);
        // 0.1 m along the flange's z, which points down at home.
        let tcp = tcp_pose(&q, &[0.0, 0.0, 0.1, 0.0, 0.0, 0.0]);
        assert!((tcp[2] - (flange[2] - 0.1)).abs() < 1e-9 && (tcp[0] - flange[0]).abs() < 1e-9, "{tcp:?}");
    }
}
