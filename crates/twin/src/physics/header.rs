//! The MJCF header every scene shares: compiler, options and the contacts' defaults, from the
//! scenario's physics settings.

use super::config::{Cone, Integrator, PhysicsConfig, Solver};
use super::template::{num, nums};

/// The `<compiler>`, `<option>` and contact `<default>` every scene (and validation scene) shares.
/// Energy is enabled for the runaway check of a scene loaded elsewhere (a run's compiled model turns
/// MuJoCo's per-step energies off and computes the kinetic energy itself: `SceneModel::build`);
/// constraint islands are off (the cell is one island, and
/// finding islands cost ~20 % of a step, measured with `perf stat` on `tendril physics-check`).
pub fn header(p: &PhysicsConfig) -> String {
    let integrator = match p.integrator {
        Integrator::Euler => "Euler",
        Integrator::Rk4 => "RK4",
        Integrator::Implicit => "implicit",
        Integrator::Implicitfast => "implicitfast",
        Integrator::Discrete => "discrete",
    };
    let cone = match p.cone {
        Cone::Pyramidal => "pyramidal",
        Cone::Elliptic => "elliptic",
    };
    let solver = match p.solver {
        Solver::Newton => "Newton",
        Solver::Cg => "CG",
        Solver::Pgs => "PGS",
    };
    format!(
        r#"<compiler angle="radian" autolimits="true"/>
  <option timestep="{dt}" integrator="{integrator}" cone="{cone}" impratio="{imp}" solver="{solver}"
          iterations="{it}" tolerance="{tol}" ls_iterations="{ls}" noslip_iterations="{ns}"
          noslip_tolerance="{nstol}">
    <flag energy="enable" island="disable"/>
  </option>
  <default>
    <geom solref="{tc} {dr}" solimp="{si} 0.5 2"/>
  </default>"#,
        dt = num(p.timestep_s),
        imp = num(p.impratio),
        it = p.iterations,
        tol = num(p.tolerance),
        ls = p.ls_iterations,
        ns = p.noslip_iterations,
        nstol = num(p.noslip_tolerance),
        tc = num(p.contact_timeconst_s),
        dr = num(p.contact_dampratio),
        si = nums(&p.contact_solimp),
    )
}
