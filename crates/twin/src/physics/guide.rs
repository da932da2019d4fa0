//! The guide's walls left out of the collision search while they cannot touch the strip (issue 39,
//! lever 3).
//!
//! The two walls of the guide slot (models/finger.xml) hold the strip straight while it is inside
//! the guide. Once the strip has grown out, its root stands at the guide's exit and the walls
//! touch nothing, yet MuJoCo tests them against every strip link each step (the scene's only
//! box-box tests). [`GuidePruning`] holds a copy of the compiled model in which the walls collide
//! with nothing (the same bodies, joints and state layout: only their contact bits differ) and
//! tells, from the positions a step's collision search starts from, whether the walls could have
//! touched anything in that step. A run ([`super::Scene`]) steps the copy while they cannot,
//! checks every step it took there with the positions MuJoCo used, and takes a step again on the
//! full model, from the state it started at, when the walls might have touched: so it finds
//! the same contacts, step for step, and gives the same trace (tests/guide_pruning.rs; the
//! numbers in docs/studies/levers.md).

use mujoco_rs::mujoco_c::_mjtObjBase;
use mujoco_rs::prelude::{MjData, MjModel};
use std::sync::Arc;

/// The compiled model without the guide walls' contacts, and the test of when it may be stepped.
#[derive(Debug)]
pub struct GuidePruning {
    model: Arc<MjModel>,
    /// qpos addresses of the growth slide and of the first link's hinge.
    growth_qpos: usize,
    curl_qpos: usize,
    /// Where the first hinge stands at zero growth, behind the walls' end (along the guide) \[m\].
    hinge_depth_at_zero_growth_m: f64,
    /// The gap between the strip's faces and the walls' inner faces \[m\].
    gap_m: f64,
    /// The strip's half thickness \[m\].
    half_thickness_m: f64,
    /// The body the walls belong to (the hand): the frame of the test.
    hand_body: usize,
    /// The walls' boxes in the hand's frame: centre and half sizes \[m\].
    walls: Vec<([f64; 3], [f64; 3])>,
    /// The first link's geom, cleared by the growth rather than by its box.
    first_link: usize,
    /// Every geom the walls' contact bits let them touch.
    candidates: Vec<usize>,
}

impl GuidePruning {
    /// The pruned copy of `model`, or `None` when the scene is not the one this reasoning holds
    /// for (no guide walls, a growth joint that is not a slide along the guide's axis, a first
    /// link that does not start at its hinge or bends about another axis, walls that are not
    /// the hand's axis-aligned boxes with a gap to the strip): then the run keeps the walls
    /// throughout.
    pub fn new(model: &MjModel) -> Option<GuidePruning> {
        let geom = |n: &str| model.name_to_id(_mjtObjBase::mjOBJ_GEOM, n);
        let joint = |n: &str| model.name_to_id(_mjtObjBase::mjOBJ_JOINT, n);
        let walls = [geom("guide_wall_in")?, geom("guide_wall_out")?];
        let (seg0, curl0, growth) = (geom("seg0")?, joint("curl0")?, joint("growth")?);
        let root = model.jnt_bodyid()[growth] as usize;
        let (pos, size) = (model.geom_pos(), model.geom_size());
        let hinge_ok = model.jnt_axis()[curl0] == [0.0, 0.0, 1.0]
            && model.jnt_pos()[curl0] == [0.0, 0.0, 0.0]
            && model.body_parentid()[model.jnt_bodyid()[curl0] as usize] as usize == root
            && model.body_pos()[model.jnt_bodyid()[curl0] as usize] == [0.0, 0.0, 0.0];
        // The strip's root slides along the guide's axis (the hand's x, through y = 0).
        let slide_ok = model.jnt_axis()[growth] == [1.0, 0.0, 0.0]
            && model.jnt_pos()[growth] == [0.0, 0.0, 0.0]
            && model.body_pos()[root][1] == 0.0;
        // The first link's box runs from its hinge along +x (finger_segment.xml).
        let link_ok = (pos[seg0][0] - size[seg0][0]).abs() < 1e-12 && pos[seg0][1] == 0.0;
        let walls_ok = walls.iter().all(|&w| model.geom_bodyid()[w] == model.body_parentid()[root]);
        if !(hinge_ok && slide_ok && link_ok && walls_ok) {
            return None;
        }
        // The gap between the strip's faces and the walls' inner faces (0.2 mm, compose.rs: wall_y).
        let r = size[seg0][1];
        let gap_m = walls.iter().map(|&w| pos[w][1].abs() - size[w][1] - r).fold(f64::INFINITY, f64::min);
        if gap_m <= 0.0 {
            return None;
        }
        let walls_end_x = walls.iter().map(|&w| pos[w][0] + size[w][0]).fold(f64::NEG_INFINITY, f64::max);
        let hand = model.geom_bodyid()[walls[0]] as usize;
        let ngeom = model.ffi().ngeom as usize;
        let (contype, conaffinity) = (model.geom_contype(), model.geom_conaffinity());
        let candidates = (0..ngeom)
            .filter(|&g| model.geom_bodyid()[g] as usize != hand)
            .filter(|&g| walls.iter().any(|&w| contype[g] & conaffinity[w] != 0 || contype[w] & conaffinity[g] != 0))
            .collect();
        // The walls are axis-aligned boxes of the hand (finger.xml); a turned wall is not this model.
        if walls.iter().any(|&w| model.geom_quat()[w] != [1.0, 0.0, 0.0, 0.0]) {
            return None;
        }
        let wall_boxes = walls.iter().map(|&w| (pos[w], size[w])).collect();
        let mut pruned = model.clone();
        for w in walls {
            pruned.geom_conaffinity_mut()[w] = 0;
            pruned.geom_contype_mut()[w] = 0;
        }
        // MuJoCo filters body pairs by the OR of their geoms' bits first (the compiler's
        // body_contype / body_conaffinity): recomputed, so the hand's body pairs with the strip's
        // links are skipped as a whole, not only geom by geom.
        let (mut body_contype, mut body_conaffinity) = (0, 0);
        for g in (0..ngeom).filter(|&g| model.geom_bodyid()[g] as usize == hand) {
            body_contype |= pruned.geom_contype()[g];
            body_conaffinity |= pruned.geom_conaffinity()[g];
        }
        pruned.body_contype_mut()[hand] = body_contype;
        pruned.body_conaffinity_mut()[hand] = body_conaffinity;
        Some(GuidePruning {
            model: Arc::new(pruned),
            growth_qpos: model.jnt_qposadr()[growth] as usize,
            curl_qpos: model.jnt_qposadr()[curl0] as usize,
            // The hinge stands at the root's x plus the growth (the slide along +x).
            hinge_depth_at_zero_growth_m: walls_end_x - model.body_pos()[root][0],
            gap_m,
            half_thickness_m: r,
            hand_body: hand,
            walls: wall_boxes,
            first_link: seg0,
            candidates,
        })
    }

    /// The model without the walls' contacts.
    pub fn model(&self) -> &Arc<MjModel> {
        &self.model
    }

    /// Whether the first link, posed by `qpos`, stands clear of the walls. Its hinge stands `e`
    /// behind the walls' end (inside the guide; negative: out of it), turned by θ: a point of the
    /// link at distance s along it and u across (|u| ≤ r, the half thickness) lies at
    /// x = -e + s cos θ - u sin θ and y = s sin θ + u cos θ from the hinge. It is inside the guide
    /// (x < 0) only for s < (e + r sin θ) / cos θ, where |y| < (e + r sin θ) tan θ + r: the link
    /// cannot cross the gap to a wall while (e + r sin θ) tan θ is at most the gap.
    pub fn first_link_clear(&self, qpos: &[f64]) -> bool {
        let e = self.hinge_depth_at_zero_growth_m - qpos[self.growth_qpos];
        let theta = qpos[self.curl_qpos].abs();
        theta < std::f64::consts::FRAC_PI_2 && (e + self.half_thickness_m * theta.sin()) * theta.tan() <= self.gap_m
    }

    /// Whether the walls cannot have touched anything at the positions `data`'s last kinematics
    /// were computed at (a step's collision search runs on them), the first link posed as
    /// `first_link_clear` says there. Conservative: every geom the walls could touch has its
    /// box, bounded in the hand's frame, clear of both walls' boxes; the first link, which stands
    /// at the guide's exit, may instead be cleared by its pose
    /// ([`GuidePruning::first_link_clear`]).
    pub fn walls_idle(&self, data: &MjData<Arc<MjModel>>, first_link_clear: bool) -> bool {
        let model = data.model();
        let (hp, hr) = (data.xpos()[self.hand_body], data.xmat()[self.hand_body]);
        // A world point in the hand's frame (MuJoCo's xmat: row-major, local to world).
        let to_hand =
            |p: [f64; 3]| -> [f64; 3] { std::array::from_fn(|k| (0..3).map(|i| hr[3 * i + k] * (p[i] - hp[i])).sum()) };
        self.candidates.iter().filter(|&&g| !(first_link_clear && g == self.first_link)).all(|&g| {
            // First the geom's bounding sphere (cheap; most links are far from the guide), then
            // its bounding box turned into the hand's frame.
            let (gp, gr, aabb) = (data.geom_xpos()[g], data.geom_xmat()[g], model.geom_aabb()[g]);
            let origin = to_hand(gp);
            let rbound = model.geom_rbound()[g];
            let far = |(wc, ws): &([f64; 3], [f64; 3])| {
                let gap: f64 = (0..3).map(|k| ((origin[k] - wc[k]).abs() - ws[k]).max(0.0).powi(2)).sum();
                gap > rbound * rbound
            };
            if self.walls.iter().all(far) {
                return true;
            }
            let centre = to_hand(std::array::from_fn(|i| gp[i] + (0..3).map(|j| gr[3 * i + j] * aabb[j]).sum::<f64>()));
            // Half extents along the hand's axes of the box turned by R = hrᵀ gr.
            let half: [f64; 3] = std::array::from_fn(|k| {
                (0..3)
                    .map(|j| {
                        let r_kj: f64 = (0..3).map(|i| hr[3 * i + k] * gr[3 * i + j]).sum();
                        r_kj.abs() * aabb[3 + j]
                    })
                    .sum()
            });
            self.walls.iter().all(|(wc, ws)| (0..3).any(|k| (centre[k] - wc[k]).abs() > half[k] + ws[k]))
        })
    }
}
