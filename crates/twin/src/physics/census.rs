//! [`ContactCensus`]: how often each pair of geoms was in contact over a run, step by step.
//!
//! A measurement, not part of the physics: it says which of the pairs MuJoCo tests every step
//! ever touch, so that pairs that never do can be left out of the collision search (issue 39,
//! lever 3; docs/studies/levers.md). Counting reads the contacts after each step and changes
//! nothing in the run.

use mujoco_rs::mujoco_c::_mjtObjBase;
use mujoco_rs::prelude::{MjData, MjModel};
use std::collections::BTreeMap;
use std::sync::Arc;

/// How one pair of geoms touched over the steps counted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairTally {
    /// Steps with at least one contact between the pair.
    pub steps: u64,
    /// Contacts summed over those steps (a box on a box may touch at up to four points).
    pub contacts: u64,
    /// Cell time of the first and the last step with a contact \[s\].
    pub first_s: f64,
    /// See `first_s`.
    pub last_s: f64,
}

/// Contacts per geom pair over the steps counted (see the module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactCensus {
    /// Steps counted.
    pub steps: u64,
    /// Per pair of geom ids (the lower first), what touched; [`ContactCensus::named`] names them.
    pub by_id: BTreeMap<(usize, usize), PairTally>,
}

impl ContactCensus {
    /// Counts the contacts MuJoCo found in the step just taken (`data.contact`, computed from the
    /// state at the step's start), at cell time `time_s`.
    pub fn record(&mut self, data: &MjData<Arc<MjModel>>, time_s: f64) {
        self.steps += 1;
        let mut seen_this_step: Vec<(usize, usize)> = Vec::new();
        for c in data.contact() {
            let (a, b) = (c.geom1 as usize, c.geom2 as usize);
            let key = (a.min(b), a.max(b));
            let tally =
                self.by_id.entry(key).or_insert(PairTally { steps: 0, contacts: 0, first_s: time_s, last_s: time_s });
            tally.contacts += 1;
            tally.last_s = time_s;
            if !seen_this_step.contains(&key) {
                seen_this_step.push(key);
                tally.steps += 1;
            }
        }
    }

    /// The tallies under the geoms' names in `model`.
    pub fn named(&self, model: &MjModel) -> Vec<(String, String, PairTally)> {
        self.by_id.iter().map(|(&(a, b), t)| (geom_name(model, a), geom_name(model, b), *t)).collect()
    }

    /// The pairs that may collide under MuJoCo's filter (contype of one against conaffinity of the
    /// other, not within one welded body, not between a body and its parent unless one of them
    /// is welded to the world), by geom name: what the collision search may test every step,
    /// whether or not the pair ever touches.
    pub fn candidate_pairs(model: &MjModel) -> Vec<(String, String)> {
        let ngeom = model.ffi().ngeom as usize;
        let (contype, conaffinity, body) = (model.geom_contype(), model.geom_conaffinity(), model.geom_bodyid());
        let (parent, weld) = (model.body_parentid(), model.body_weldid());
        let mut out = Vec::new();
        for a in 0..ngeom {
            for b in a + 1..ngeom {
                let (wa, wb) = (weld[body[a] as usize] as usize, weld[body[b] as usize] as usize);
                let filtered = contype[a] & conaffinity[b] == 0 && contype[b] & conaffinity[a] == 0;
                let parent_of = |child: usize| weld[parent[child] as usize] as usize;
                let family = wa == wb || (wa != 0 && wb != 0 && (parent_of(wa) == wb || parent_of(wb) == wa));
                if !filtered && !family {
                    out.push((geom_name(model, a), geom_name(model, b)));
                }
            }
        }
        out
    }
}

/// A geom's name in `model` (`geom<id>` for an unnamed one; `flex` for a contact's flex side,
/// which has no geom: MuJoCo's -1).
fn geom_name(model: &MjModel, g: usize) -> String {
    if g >= model.ffi().ngeom as usize {
        return "flex".into();
    }
    model.id_to_name(_mjtObjBase::mjOBJ_GEOM, g).map_or_else(|| format!("geom{g}"), str::to_string)
}
