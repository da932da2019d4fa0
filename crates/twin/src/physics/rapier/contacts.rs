//! MuJoCo's contact rules, applied to rapier's contacts: which geom pairs collide and with what
//! friction. Both come from the compiled model, so a scene collides the same pairs on both backends.

use mujoco_rs::prelude::MjModel;
use rapier3d_f64::prelude::*;

/// Per geom pair: `None` if the pair never collides, else its sliding friction coefficient.
#[derive(Debug, Clone)]
pub struct ContactRules {
    ngeom: usize,
    pairs: Vec<Option<f64>>,
}

impl ContactRules {
    /// The rules of `m`: MuJoCo's collision filter (contype/conaffinity bits either way, never
    /// within one welded body, never between a body and its parent unless that is the world) and
    /// its friction mix (the geom with the higher `priority` sets the friction, else the larger
    /// of the two).
    pub fn from_model(m: &MjModel) -> ContactRules {
        let ngeom = m.ffi().ngeom as usize;
        let weld = |g: usize| m.body_weldid()[m.geom_bodyid()[g] as usize] as usize;
        let weld_parent = |w: usize| m.body_weldid()[m.body_parentid()[w] as usize] as usize;
        let mut pairs = vec![None; ngeom * ngeom];
        for a in 0..ngeom {
            for b in 0..ngeom {
                let bits = (m.geom_contype()[a] & m.geom_conaffinity()[b]) != 0
                    || (m.geom_contype()[b] & m.geom_conaffinity()[a]) != 0;
                let (wa, wb) = (weld(a), weld(b));
                let same_body = wa == wb;
                let parent_child = wa != 0 && wb != 0 && (wa == weld_parent(wb) || wb == weld_parent(wa));
                if a == b || !bits || same_body || parent_child {
                    continue;
                }
                let (pa, pb) = (m.geom_priority()[a], m.geom_priority()[b]);
                let (fa, fb) = (m.geom_friction()[a][0], m.geom_friction()[b][0]);
                pairs[a * ngeom + b] = Some(match pa.cmp(&pb) {
                    std::cmp::Ordering::Greater => fa,
                    std::cmp::Ordering::Less => fb,
                    std::cmp::Ordering::Equal => fa.max(fb),
                });
            }
        }
        ContactRules { ngeom, pairs }
    }

    /// Whether geoms `a` and `b` may collide at all.
    pub fn collide(&self, a: usize, b: usize) -> bool {
        self.friction(a, b).is_some()
    }

    /// The pair's friction, `None` when it does not collide.
    pub fn friction(&self, a: usize, b: usize) -> Option<f64> {
        if a >= self.ngeom || b >= self.ngeom {
            return None;
        }
        self.pairs[a * self.ngeom + b]
    }

    fn geoms(&self, colliders: &ColliderSet, c1: ColliderHandle, c2: ColliderHandle) -> Option<(usize, usize)> {
        Some((colliders.get(c1)?.user_data as usize, colliders.get(c2)?.user_data as usize))
    }
}

impl PhysicsHooks for ContactRules {
    fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
        let (a, b) = self.geoms(context.colliders, context.collider1, context.collider2)?;
        self.collide(a, b).then(SolverFlags::default)
    }

    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        let Some((a, b)) = self.geoms(context.colliders, context.collider1, context.collider2) else {
            return;
        };
        let friction = self.friction(a, b);
        if let (Some(mu), Some(manifold)) = (friction, context.rigid_mut()) {
            *manifold.friction = mu;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{PhysicsConfig, SceneModel, SceneSpec, validation};
    use mujoco_rs::mujoco_c::_mjtObjBase::mjOBJ_GEOM;

    fn geom(m: &MjModel, name: &str) -> usize {
        m.name_to_id(mjOBJ_GEOM, name).unwrap()
    }

    #[test]
    fn pads_touch_the_box_not_each_other() {
        let m = validation::pinch(&PhysicsConfig::default(), 0.7).unwrap();
        let rules = ContactRules::from_model(&m);
        let (l, r, b) = (geom(&m, "pad_l"), geom(&m, "pad_r"), geom(&m, "box"));
        assert_eq!(rules.friction(l, b), Some(0.7));
        assert_eq!(rules.friction(b, r), Some(0.7));
        assert!(!rules.collide(l, r));
    }

    #[test]
    fn the_object_sets_the_grip_friction_and_the_strip_skips_its_own_joints() {
        let scene = SceneModel::build(&SceneSpec::default()).unwrap();
        let m = scene.model();
        let rules = ContactRules::from_model(m);
        // priority 1 on the object: its 1.07 wins over the strip's default 1.
        assert_eq!(
            rules.friction(geom(m, "seg3"), geom(m, "object_grip")),
            Some(m.geom_friction()[geom(m, "object_grip")][0])
        );
        // The guide walls hold the strip; the strip never touches itself or the table.
        assert!(rules.collide(geom(m, "guide_wall_in"), geom(m, "seg0")));
        assert!(!rules.collide(geom(m, "seg1"), geom(m, "seg2")));
        assert!(!rules.collide(geom(m, "seg1"), geom(m, "table")));
    }
}
