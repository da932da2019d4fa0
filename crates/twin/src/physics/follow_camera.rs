//! The scene's `follow` camera: a camera of the model that follows the object through every
//! phase, so MuJoCo's own viewers reach a moving view with one key (`]` in `tendril view` and in
//! MuJoCo's `simulate`) and `tendril render --camera follow` draws it.
//!
//! It rides on the arm's first link (`link1`, which turns with the base joint) and MuJoCo aims it
//! at the object's centre of mass (`mode="targetbodycom"`, world z up) at every step. It starts at
//! [`DEFAULT_VIEWPOINT`] from the object's wrap point (where the finger holds it, as `tendril
//! render`'s tracking camera starts), so as the arm swings the object about its base the camera
//! swings with it, and the arm stays behind the object instead of passing between the two (a
//! camera fixed in the world's directions, tried first, lost the crimper behind the forearm in the
//! transfer). A produce item (its flex has no body of its own) is followed through the hand.
//! `models/ur5e.xml` says where the camera goes (`${camera}` in `link1`); a scene without an object
//! has none.

/// Name of the camera that follows the object.
pub const FOLLOW_CAMERA: &str = "follow";

/// Where a camera looks at a point from: MuJoCo's free-camera angles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewpoint {
    /// Distance from the point \[m\].
    pub distance_m: f64,
    /// Azimuth \[°\], MuJoCo's: the camera looks along (cos az, sin az) in the horizontal plane.
    pub azimuth_deg: f64,
    /// Elevation \[°\] (negative: from above).
    pub elevation_deg: f64,
}

/// The viewpoint pictures of the cell start from: 0.35 m from the grip, from 135° and 20° above,
/// so the grip and the finger around it fill a 45° field. A stated choice.
pub const DEFAULT_VIEWPOINT: Viewpoint = Viewpoint { distance_m: 0.35, azimuth_deg: 135.0, elevation_deg: -20.0 };

impl Viewpoint {
    /// Where a camera stands to look at `target` \[m\] from this viewpoint.
    pub fn position(&self, target: [f64; 3]) -> [f64; 3] {
        let (az, el) = (self.azimuth_deg.to_radians(), self.elevation_deg.to_radians());
        let forward = [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()];
        std::array::from_fn(|k| target[k] - self.distance_m * forward[k])
    }
}

/// The `follow` camera's MJCF element in `link1`, aimed at body `target`, placed at
/// [`DEFAULT_VIEWPOINT`] from `look_at` (world frame \[m\]) when the base joint is at `pan_rad`.
/// `link1`'s origin is the world's (the arm's base stands at the origin, as the kinematics in
/// `tendril-ur5e` take it), its frame the world's turned by the base joint about z.
pub fn element(look_at: [f64; 3], pan_rad: f64, target: &str) -> String {
    let world = DEFAULT_VIEWPOINT.position(look_at);
    let (s, c) = (-pan_rad).sin_cos();
    let local = [c * world[0] - s * world[1], s * world[0] + c * world[1], world[2]];
    format!(
        "<camera name=\"{FOLLOW_CAMERA}\" mode=\"targetbodycom\" target=\"{target}\" pos=\"{:.6} {:.6} {:.6}\" fovy=\"45\"/>",
        local[0], local[1], local[2]
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_position_looks_at_the_target_from_the_viewpoint() {
        let target = [0.1, -0.2, 0.3];
        let pos = DEFAULT_VIEWPOINT.position(target);
        let d: Vec<f64> = (0..3).map(|k| target[k] - pos[k]).collect();
        let dist = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((dist - 0.35).abs() < 1e-12, "{dist}");
        // Looking down 20°, along azimuth 135°.
        assert!(((d[2] / dist).asin().to_degrees() + 20.0).abs() < 1e-9);
        assert!((d[1].atan2(d[0]).to_degrees() - 135.0).abs() < 1e-9);
    }

    #[test]
    fn the_element_puts_the_camera_at_the_viewpoint_in_the_turned_link() {
        let look_at = [0.4, 0.3, 0.2];
        let world = DEFAULT_VIEWPOINT.position(look_at);
        let pan = 0.7_f64;
        let text = element(look_at, pan, "object");
        let pos: Vec<f64> = text
            .split("pos=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .split(' ')
            .map(|v| v.parse().unwrap())
            .collect();
        // link1 turned by the pan angle takes the local position back to the world one.
        let (s, c) = pan.sin_cos();
        let back = [c * pos[0] - s * pos[1], s * pos[0] + c * pos[1], pos[2]];
        for k in 0..3 {
            assert!((back[k] - world[k]).abs() < 1e-6, "{back:?} vs {world:?}");
        }
        assert!(text.contains("mode=\"targetbodycom\" target=\"object\""), "{text}");
    }
}
