//! A produce item during a MuJoCo run: where it is, what presses it and how hard, its stem, and
//! whether its flex turned itself inside out.

use super::damage::{DamageTally, PatchAt, Toucher, patch_of};
use super::produce::{FLEX_NAME, ProduceItem};
use super::{Divergence, PhysicsError};
use mujoco_rs::mujoco_c::{_mjtGeomBase, _mjtObjBase};
use mujoco_rs::prelude::{MjData, MjModel};
use std::ops::Range;

/// Gravity's acceleration \[m/s²\] (MuJoCo's default, which the scene keeps).
const G_M_S2: f64 = 9.81;

/// The flex's elements, vertices and nodes in the compiled scene.
#[derive(Debug, Clone)]
pub(crate) struct ProduceIds {
    /// The flex's id.
    pub(crate) flex: usize,
    /// Its node bodies, and each one's first degree of freedom (three slides along world x, y, z).
    pub(crate) nodes: Vec<(usize, usize)>,
    /// Each node's mass \[kg\].
    pub(crate) node_mass: Vec<f64>,
    /// Its vertices in `flexvert_xpos`.
    pub(crate) verts: Range<usize>,
    /// Its tetrahedra, four vertex ids each (relative to `verts.start`).
    pub(crate) tets: Vec<[usize; 4]>,
    /// The nodes the item's top moves with, and their weights: the nodes nearest the top centre
    /// of the bounding box, equally (trilinear: the top face's four corners; quadratic: its
    /// centre node).
    pub(crate) top: Vec<(usize, f64)>,
}

impl ProduceIds {
    /// Finds the produce flex in a compiled scene.
    pub(crate) fn find(m: &MjModel) -> Result<ProduceIds, PhysicsError> {
        let flex = m
            .name_to_id(_mjtObjBase::mjOBJ_FLEX, FLEX_NAME)
            .ok_or_else(|| PhysicsError::Missing { kind: "flex", name: FLEX_NAME.into() })?;
        let adr = m.flex_nodeadr()[flex] as usize;
        let bodies = &m.flex_nodebodyid()[adr..adr + m.flex_nodenum()[flex] as usize];
        let nodes: Vec<(usize, usize)> =
            bodies.iter().map(|&b| (b as usize, m.body_dofadr()[b as usize] as usize)).collect();
        let node_mass = nodes.iter().map(|&(b, _)| m.body_mass()[b]).collect();
        let verts = (m.flex_vertadr()[flex] as usize)..(m.flex_vertadr()[flex] + m.flex_vertnum()[flex]) as usize;
        let dim = m.flex_dim()[flex] as usize;
        let data = m.flex_elemdataadr()[flex] as usize;
        let tets = (0..m.flex_elemnum()[flex] as usize)
            .filter(|_| dim == 3)
            .map(|e| std::array::from_fn(|k| m.flex_elem()[data + 4 * e + k] as usize))
            .collect();
        // Node positions at qpos0 (their bodies' frames: the flex's frame body is static).
        let pos: Vec<[f64; 3]> = nodes.iter().map(|&(b, _)| m.body_pos()[b]).collect();
        let top_z = pos.iter().map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max);
        let cx = pos.iter().map(|p| p[0]).sum::<f64>() / pos.len() as f64;
        let cy = pos.iter().map(|p| p[1]).sum::<f64>() / pos.len() as f64;
        let on_top: Vec<usize> = (0..pos.len()).filter(|&i| (pos[i][2] - top_z).abs() < 1e-9).collect();
        let reach = |i: usize| (pos[i][0] - cx).hypot(pos[i][1] - cy);
        let nearest = on_top.iter().map(|&i| reach(i)).fold(f64::INFINITY, f64::min);
        let top_nodes: Vec<usize> = on_top.into_iter().filter(|&i| reach(i) < nearest + 1e-9).collect();
        let w = 1.0 / top_nodes.len() as f64;
        Ok(ProduceIds { flex, nodes, node_mass, verts, tets, top: top_nodes.into_iter().map(|i| (i, w)).collect() })
    }
}

/// What one geom is to the damage figures: who it is and its principal curvatures \[1/m\] and
/// extent \[m\].
#[derive(Debug, Clone, Copy)]
pub(crate) struct GeomShape {
    toucher: Toucher,
    curvatures: [f64; 2],
    length_m: f64,
}

impl GeomShape {
    /// Geom `g`'s shape in `m`: a sphere is curved both ways, a capsule or cylinder one way, a
    /// box, plane or anything else flat.
    pub(crate) fn of(m: &MjModel, g: usize, toucher: Toucher) -> GeomShape {
        let size = m.geom_size()[g];
        let (curvatures, length_m) = match m.geom_type()[g] {
            _mjtGeomBase::mjGEOM_SPHERE => ([1.0 / size[0]; 2], 2.0 * size[0]),
            _mjtGeomBase::mjGEOM_CAPSULE | _mjtGeomBase::mjGEOM_CYLINDER => ([1.0 / size[0], 0.0], 2.0 * size[1]),
            _mjtGeomBase::mjGEOM_BOX => ([0.0; 2], 2.0 * size[0].max(size[1]).max(size[2])),
            _ => ([0.0; 2], 1.0),
        };
        GeomShape { toucher, curvatures, length_m }
    }
}

/// The stem that holds a harvested item to its plant until it lets go: a tension-only spring of
/// stiffness `k` and rest length `rest_m` from a fixed point above the item's top, critically
/// damped on the item's mass, applied to the nodes the top moves with.
#[derive(Debug, Clone)]
pub(crate) struct Stem {
    anchor: [f64; 3],
    rest_m: f64,
    stiffness_n_m: f64,
    damping_n_s_m: f64,
    detach_n: f64,
    /// Tension at the last step \[N\].
    pub(crate) tension_n: f64,
    /// The largest tension so far \[N\].
    pub(crate) max_tension_n: f64,
    /// When it let go \[s\] (`None`: still attached).
    pub(crate) detached_s: Option<f64>,
}

/// The stem's length below the plant \[m\]: 20 mm, a stated choice (a tomato's pedicel or a
/// strawberry's peduncle is one to a few centimetres).
pub const STEM_LENGTH_M: f64 = 0.02;

/// What a run reads of its produce item after a step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ProduceReadout {
    /// The contact pressure on it so far, and at the last step.
    pub damage: DamageTally,
    /// Whether it started on its plant (a harvest).
    pub harvest: bool,
    /// The stem's tension at the last step \[N\] (0 without a stem or once it let go).
    pub stem_tension_n: f64,
    /// The stem's largest tension so far \[N\].
    pub max_stem_tension_n: f64,
    /// When the stem let go \[s\] (`None`: still attached, or no stem).
    pub detached_s: Option<f64>,
    /// The normal force on the sensor pad's bump alone \[N\] (the pad's force is the bump's and
    /// the casing's): on soft flesh the bump sinks in and the casing takes a share.
    pub bump_force_n: f64,
}

/// A produce item's state over a run.
#[derive(Debug, Clone)]
pub(crate) struct ProduceRun {
    /// The damage so far.
    pub(crate) tally: DamageTally,
    /// The stem, when the item is harvested.
    pub(crate) stem: Option<Stem>,
    /// Each tetrahedron's signed volume at the start \[m³\].
    start_volumes: Vec<f64>,
    /// Contact patches of the last step, reused.
    patches: Vec<PatchAt>,
}

/// Signed volume of the tetrahedron `t` of vertices `x` \[m³\].
fn volume(x: &[[f64; 3]], t: &[usize; 4]) -> f64 {
    let d = |k: usize| std::array::from_fn::<f64, 3, _>(|i| x[t[k]][i] - x[t[0]][i]);
    let (a, b, c) = (d(1), d(2), d(3));
    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0
}

impl ProduceRun {
    /// The item's state at the start of a run on `data` (positions computed); a harvest hangs
    /// it from a stem of `stem_stiffness_n_m` whose anchor holds its weight.
    pub(crate) fn start(
        ids: &ProduceIds,
        item: &ProduceItem,
        data: &MjData<std::sync::Arc<MjModel>>,
        harvest: Option<f64>,
    ) -> ProduceRun {
        let x = &data.flexvert_xpos()[ids.verts.clone()];
        let start_volumes = ids.tets.iter().map(|t| volume(x, t)).collect();
        let stem = harvest.map(|stiffness_n_m| {
            let top = top_point(ids, data);
            let weight = item.mass_kg * G_M_S2;
            // Critical damping on the item's mass: 2 √(k m).
            let damping_n_s_m = 2.0 * (stiffness_n_m * item.mass_kg).sqrt();
            Stem {
                anchor: [top[0], top[1], top[2] + STEM_LENGTH_M + weight / stiffness_n_m],
                rest_m: STEM_LENGTH_M,
                stiffness_n_m,
                damping_n_s_m,
                detach_n: item.properties.detach_n.unwrap_or(f64::INFINITY),
                tension_n: weight,
                max_tension_n: weight,
                detached_s: None,
            }
        });
        ProduceRun { tally: DamageTally::default(), stem, start_volumes, patches: Vec::new() }
    }

    /// Sets the forces on the item's nodes for the next step: `push_n` (a disturbance, world
    /// frame) shared by mass, and the stem's pull on the top (its tension from the last step's
    /// positions and velocities; it lets go when the tension reaches the detachment force).
    pub(crate) fn apply_forces(
        &mut self,
        ids: &ProduceIds,
        data: &mut MjData<std::sync::Arc<MjModel>>,
        time_s: f64,
        push_n: [f64; 3],
    ) {
        let pull = self.stem_pull(ids, data, time_s);
        let total: f64 = ids.node_mass.iter().sum();
        for (i, &(body, _)) in ids.nodes.iter().enumerate() {
            let share = ids.node_mass[i] / total;
            let top = ids.top.iter().find(|t| t.0 == i).map_or(0.0, |t| t.1);
            let f: [f64; 3] = std::array::from_fn(|k| share * push_n[k] + top * pull[k]);
            data.xfrc_applied_mut()[body] = [f[0], f[1], f[2], 0.0, 0.0, 0.0];
        }
    }

    /// The stem's pull on the item's top this step \[N\] (zero without a stem, or once it let go).
    fn stem_pull(&mut self, ids: &ProduceIds, data: &MjData<std::sync::Arc<MjModel>>, time_s: f64) -> [f64; 3] {
        let Some(stem) = self.stem.as_mut() else { return [0.0; 3] };
        if stem.detached_s.is_some() {
            return [0.0; 3];
        }
        let p = top_point(ids, data);
        let v = top_velocity(ids, data);
        let gap: [f64; 3] = std::array::from_fn(|k| stem.anchor[k] - p[k]);
        let length = (gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2]).sqrt();
        let u = gap.map(|g| g / length.max(1e-12));
        // The stem lengthens at −u·v; it only pulls.
        let lengthening = -(u[0] * v[0] + u[1] * v[1] + u[2] * v[2]);
        let stretch = length - stem.rest_m;
        let elastic = stem.stiffness_n_m * stretch.max(0.0);
        let tension = if stretch > 0.0 { (elastic + stem.damping_n_s_m * lengthening).max(0.0) } else { 0.0 };
        stem.tension_n = tension;
        stem.max_tension_n = stem.max_tension_n.max(tension);
        // The stem lets go on its elastic tension: a published detachment force is a slow
        // (quasi-static) pull-off test's, and the damping stands in for the plant's resistance to
        // motion, not for load on the abscission zone.
        if elastic >= stem.detach_n {
            stem.detached_s = Some(time_s);
            stem.tension_n = 0.0;
            return [0.0; 3];
        }
        u.map(|c| c * tension)
    }

    /// Records the step's contact pressure on the item: one patch per geom that touches it.
    pub(crate) fn record_damage(
        &mut self,
        ids: &ProduceIds,
        item: &ProduceItem,
        shapes: &[Option<GeomShape>],
        data: &MjData<std::sync::Arc<MjModel>>,
        dt_s: f64,
    ) {
        let centre = centroid(ids, data);
        // Per touching geom: summed normal force and force-weighted position.
        let mut sums: Vec<(usize, f64, [f64; 3])> = Vec::new();
        for (i, c) in data.contact().iter().enumerate() {
            let other = if c.flex[0] as usize == ids.flex && c.flex[1] < 0 {
                c.geom[1]
            } else if c.flex[1] as usize == ids.flex && c.flex[0] < 0 {
                c.geom[0]
            } else {
                continue;
            };
            if other < 0 || c.efc_address < 0 {
                continue;
            }
            let f = data.contact_force(i)[0];
            if f.is_nan() || f <= 0.0 {
                continue;
            }
            let g = other as usize;
            match sums.iter_mut().find(|s| s.0 == g) {
                Some(s) => {
                    s.1 += f;
                    for k in 0..3 {
                        s.2[k] += f * c.pos[k];
                    }
                }
                None => sums.push((g, f, c.pos.map(|p| f * p))),
            }
        }
        self.patches.clear();
        for (g, force, weighted) in sums {
            let Some(shape) = shapes.get(g).copied().flatten() else { continue };
            let dir: [f64; 3] = std::array::from_fn(|k| weighted[k] / force - centre[k]);
            self.patches.push(PatchAt {
                toucher: shape.toucher,
                force_n: force,
                patch: patch_of(item, dir, shape.curvatures, shape.length_m, force),
            });
        }
        self.tally.record(&self.patches, dt_s);
    }

    /// What the run reads of the item now.
    pub(crate) fn readout(&self) -> ProduceReadout {
        ProduceReadout {
            damage: self.tally,
            harvest: self.stem.is_some(),
            stem_tension_n: self.stem.as_ref().map_or(0.0, |s| s.tension_n),
            max_stem_tension_n: self.stem.as_ref().map_or(0.0, |s| s.max_tension_n),
            detached_s: self.stem.as_ref().and_then(|s| s.detached_s),
            bump_force_n: 0.0,
        }
    }

    /// A tetrahedron turned inside out (its signed volume changed sign), if one did: the flex has
    /// inverted and its forces mean nothing.
    pub(crate) fn inverted(&self, ids: &ProduceIds, data: &MjData<std::sync::Arc<MjModel>>) -> Option<Divergence> {
        let x = &data.flexvert_xpos()[ids.verts.clone()];
        ids.tets.iter().zip(&self.start_volumes).enumerate().find_map(|(e, (t, v0))| {
            let v = volume(x, t);
            (v * v0.signum() <= 0.0).then_some(Divergence::FlexInverted { element: e, volume_m3: v })
        })
    }
}

/// Mass-weighted centre of the item's nodes \[m\] (the item's centre of mass).
pub(crate) fn centroid(ids: &ProduceIds, data: &MjData<std::sync::Arc<MjModel>>) -> [f64; 3] {
    weighted(ids, |b, _| data.xpos()[b])
}

/// Mass-weighted velocity of the item's nodes \[m/s\] (its centre of mass's).
pub(crate) fn velocity(ids: &ProduceIds, data: &MjData<std::sync::Arc<MjModel>>) -> [f64; 3] {
    weighted(ids, |_, dof| [data.qvel()[dof], data.qvel()[dof + 1], data.qvel()[dof + 2]])
}

fn weighted(ids: &ProduceIds, of: impl Fn(usize, usize) -> [f64; 3]) -> [f64; 3] {
    let total: f64 = ids.node_mass.iter().sum();
    let mut sum = [0.0; 3];
    for (&(b, dof), m) in ids.nodes.iter().zip(&ids.node_mass) {
        let v = of(b, dof);
        for k in 0..3 {
            sum[k] += m * v[k];
        }
    }
    sum.map(|s| s / total)
}

/// The item's top point (where the stem holds it: the top face's centre of the nodes' box) \[m\].
fn top_point(ids: &ProduceIds, data: &MjData<std::sync::Arc<MjModel>>) -> [f64; 3] {
    let mut p = [0.0; 3];
    for &(n, w) in &ids.top {
        let x = data.xpos()[ids.nodes[n].0];
        for k in 0..3 {
            p[k] += w * x[k];
        }
    }
    p
}

/// The top point's velocity \[m/s\].
fn top_velocity(ids: &ProduceIds, data: &MjData<std::sync::Arc<MjModel>>) -> [f64; 3] {
    let mut v = [0.0; 3];
    for &(n, w) in &ids.top {
        let dof = ids.nodes[n].1;
        for (k, vk) in v.iter_mut().enumerate() {
            *vk += w * data.qvel()[dof + k];
        }
    }
    v
}
