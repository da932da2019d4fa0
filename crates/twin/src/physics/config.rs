//! Scenario sections `[physics]` (with `[physics.rapier]`), `[finger]` and `[object]`: every tunable of
//! the scene and of the engines that simulate it.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use tendril_config::{Checker, Validate};

/// MuJoCo's integrator (`<option integrator>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// Semi-implicit Euler (joint damping implicit).
    Euler,
    /// 4th-order Runge-Kutta.
    Rk4,
    /// Implicit in velocity (full derivatives).
    Implicit,
    /// Implicit in velocity, skipping Coriolis derivatives: damping and servo `kv` implicit, cheap.
    Implicitfast,
    /// MuJoCo's discrete integrator (3.13 on): the constraint solve and the implicit velocity
    /// update in one, in the metric `M + hD + h²K` that holds damping and stiffness. A produce
    /// item's flex elasticity needs it (MuJoCo 3.17 integrates a flex's elasticity implicitly only
    /// here).
    Discrete,
}

/// Friction cone (`<option cone>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Cone {
    /// Pyramidal approximation: creeps below the friction limit (see docs/facts.md#mujoco-pyramidal-cones-creep).
    Pyramidal,
    /// Exact Coulomb cone.
    Elliptic,
}

/// MuJoCo's constraint solver (`<option solver>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    /// Newton's method on the primal problem: a Cholesky factorisation of the constraint Hessian
    /// per iteration, few iterations.
    Newton,
    /// Conjugate gradient on the same primal problem: no factorisation, more iterations.
    Cg,
    /// Projected Gauss-Seidel on the dual problem.
    Pgs,
}

/// Which engine simulates the scene (`physics.backend`). Both run the same scene, compiled once by
/// MuJoCo from models/ (see [`super::rapier`] for how the rapier world is built from it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// MuJoCo 3.17 (soft contacts, elliptic cones, implicit integrators): the reference.
    #[default]
    Mujoco,
    /// rapier3d 0.36 (f64): reduced-coordinate multibody finger, impulse-based contacts.
    Rapier,
}

impl Backend {
    /// `physics.backend = NAME`: what `--backend` means on the command line.
    pub fn as_override(self) -> tendril_config::Override {
        tendril_config::Override { key: "physics.backend".into(), value: toml::Value::String(self.name().into()) }
    }

    /// The name as written in scenarios and summaries (`mujoco`, `rapier`).
    pub fn name(self) -> &'static str {
        match self {
            Backend::Mujoco => "mujoco",
            Backend::Rapier => "rapier",
        }
    }

    /// The arm mode a scenario gets on this backend when it does not set `physics.arm_mode`: the
    /// servoed UR5e on MuJoCo (see [`ArmMode::Dynamic`] for why), the prescribed arm on rapier,
    /// which has no other.
    pub fn default_arm_mode(self) -> ArmMode {
        match self {
            Backend::Mujoco => ArmMode::Dynamic,
            Backend::Rapier => ArmMode::Kinematic,
        }
    }
}

impl std::str::FromStr for Backend {
    type Err = String;

    fn from_str(s: &str) -> Result<Backend, String> {
        match s {
            "mujoco" => Ok(Backend::Mujoco),
            "rapier" => Ok(Backend::Rapier),
            other => Err(format!("unknown physics backend `{other}` (expected mujoco or rapier)")),
        }
    }
}

/// rapier's friction constraints for contacts between two rigid bodies (contacts with the finger,
/// a multibody, always use the Coulomb model in rapier 0.36).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RapierFriction {
    /// One friction constraint per group of contacts plus a twist constraint.
    Simplified,
    /// One Coulomb friction constraint per contact point.
    Coulomb,
}

/// `[physics.rapier]`: the rapier backend's own settings (the MuJoCo options of `[physics]`,
/// integrator, cone, impratio, solver and noslip iterations, solref/solimp, do not apply to it;
/// `timestep_s`, `arm_mode`, `arm_max_speed_rad_s` and the divergence bounds do).
///
/// Defaults chosen with tests/physics_validation.rs, which runs the analytic cases on both backends,
/// and the facts measured for rapier 0.36 in docs/facts.md#rapier-036.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RapierConfig {
    /// Solver iterations per step. 8: 4 run 1.8x faster, but in the speed/accuracy study (crimper,
    /// 5 ms, 8 links, against the MuJoCo reference) the drop lands 1.5 s off with 4 and 0.2 s with 8
    /// (force RMSE 0.14 vs 0.12 N). The facts (docs/facts.md#rapier-multibody-chain) saw a 12-link multibody chain track its spring
    /// targets to 0.03 rad at 4; the contacts with a 0.4 kg object are what want more.
    pub solver_iterations: u32,
    /// Internal PGS iterations per solver iteration.
    pub pgs_iterations: u32,
    /// Stabilisation (position-correction) iterations per solver iteration.
    pub stabilization_iterations: u32,
    /// Friction model between rigid bodies. `simplified`: docs/facts.md#rapier-friction-model measured the slip angle within
    /// 0.03 deg of atan(mu) with it, where the Coulomb model slips about 1.5 deg early.
    pub friction_model: RapierFriction,
    /// Natural frequency of the contact constraints' softness \[Hz\]. rapier's default, 30.
    pub contact_frequency_hz: f64,
    /// Damping ratio of the contact constraints' softness. Tuned: 5 (rapier's default is 10), the
    /// setting, of six tried (16/30 Hz with 1 and 5, 60 Hz with 5, 30 Hz with 10), that reproduces
    /// the most of the paper's Sec. V with MuJoCo's calibration (11 of 15 rows, `tendril reproduce
    /// gripper --backend rapier --set physics.rapier.contact_damping_ratio=...`) and passes the
    /// analytic validation: 1 reproduces 12 but lets the pinch test's pads sink 5 mm into the box
    /// (contacts too soft); 10 makes the crimper and the shampoo ring at lift-off (52 and 43 %
    /// fluctuation, limit 40 %). The no-feedback drop times move by seconds across these settings
    /// (models/README.md).
    pub contact_damping_ratio: f64,
    /// Length scale of rapier's tolerances \[m\]: slop 0.005 x, speculative margin 0.02 x. rapier is
    /// tuned for metre-sized bodies (slop 5 mm); the finger is 2 mm thick and grips 25 mm handles,
    /// so 0.02: slop 0.1 mm, margin 0.4 mm.
    pub length_unit_m: f64,
}

impl Default for RapierConfig {
    fn default() -> Self {
        RapierConfig {
            solver_iterations: 8,
            pgs_iterations: 1,
            stabilization_iterations: 1,
            friction_model: RapierFriction::Simplified,
            contact_frequency_hz: 30.0,
            contact_damping_ratio: 5.0,
            length_unit_m: 0.02,
        }
    }
}

impl Validate for RapierConfig {
    fn validate(&self, at: &mut Checker) {
        at.require("solver_iterations", (1..=1000).contains(&self.solver_iterations), || {
            format!("must be between 1 and 1000, got {}", self.solver_iterations)
        });
        at.require("pgs_iterations", (1..=100).contains(&self.pgs_iterations), || {
            format!("must be between 1 and 100, got {}", self.pgs_iterations)
        });
        at.require("stabilization_iterations", self.stabilization_iterations <= 100, || {
            format!("must be at most 100, got {}", self.stabilization_iterations)
        });
        at.in_range("contact_frequency_hz", self.contact_frequency_hz, 0.1, 10000.0);
        at.positive("contact_damping_ratio", self.contact_damping_ratio);
        at.in_range("length_unit_m", self.length_unit_m, 1e-4, 10.0);
    }
}

/// How the UR5e is simulated (`physics.arm_mode`). Not set in a scenario: the backend's
/// [`Backend::default_arm_mode`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ArmMode {
    /// Prescribed arm motion: each step the six joints get the velocities that take them to the
    /// commanded angles (rate-limited to `arm_max_speed_rad_s`), so the hand moves along the UR's
    /// trajectory and has the velocity friction needs (a mocap body would have none). The joints
    /// carry a large armature so contact forces do not move the arm within a step.
    ///
    /// On MuJoCo its answers need a finer step than the default's: while the arm moves, the wrap's
    /// contacts chatter tick to tick at 1.25 ms (the pad force by 0.028 N RMS against 0.0002 N with
    /// the dynamic arm), the frozen grip relaxes faster and the shampoo without feedback drops
    /// 0.85 s early. The chatter grows with the armature (the shampoo's drop 13.9 / 13.0 / 11.9 s at
    /// 100 / 1000 / 10 000 kg m^2) and is gone at 0.3125 ms, where the drop is the dynamic arm's
    /// (docs/studies/convergence.md#why-the-shampoos-drop-used-to-move-with-the-step-the-prescribed-arm). The only mode of the rapier backend.
    Kinematic,
    /// The six joints with masses, gravity compensation and position servos (models/ur5e.xml). The
    /// servos track the same setpoints the prescribed arm moves along (each tick's target spread
    /// over the tick), with the setpoint's velocity fed forward, as the UR's own joint controller
    /// tracks its interpolated trajectory; the hand gives way to contact forces through the servos'
    /// stiffness. MuJoCo's default: its answers hold from the default step down (the shampoo's drop
    /// without feedback 13.63 / 13.83 / 13.90 s at 2.5 / 1.25 / 0.625 ms, seed 1; README,
    /// "Convergence"), as fast as the prescribed arm (at 1.25 ms 18-20x real time against 16-19x).
    Dynamic,
}

impl ArmMode {
    /// The name as written in scenarios (`kinematic`, `dynamic`).
    pub fn name(self) -> &'static str {
        match self {
            ArmMode::Kinematic => "kinematic",
            ArmMode::Dynamic => "dynamic",
        }
    }
}

/// `[physics]`: MuJoCo options and the divergence bounds.
///
/// Defaults are the converged setting (docs/studies/convergence.md#where-it-stands): elliptic cones and a Newton solver with
/// a small tolerance (MuJoCo's advice for slip accuracy; docs/facts.md#mujoco-pyramidal-cones-creep measured that pyramidal cones
/// creep), stiff contacts that hold objects without noslip iterations, and the largest step at which
/// the Section V answers agree with half that step and the contacts keep their time constant. About
/// 30× real time on one core with the default graded finger (26-34× over three rounds of
/// benches/scenario.rs in one sitting; docs/studies/speed-accuracy.md#the-figures).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhysicsConfig {
    /// The engine (`mujoco` | `rapier`); `--backend` on the command line sets it too.
    pub backend: Backend,
    /// The folder the scene's parts (finger.xml, finger_segment.xml, sensor_pad.xml, ur5e.xml,
    /// table.xml) are read from at run time, relative to the scenario file. Not given: `models/`
    /// beside the scenario's folder if it holds finger.xml (the repository's layout), else the
    /// copies built into the binary.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub models_dir: Option<PathBuf>,
    /// Simulation step \[s\]. 2.5 ms: the largest step at which the 5 ms contacts below keep
    /// their time constant (MuJoCo stretches a time constant shorter than two steps to two steps, so
    /// at 5 ms the contacts would be 10 ms ones, a different contact model), and whose Section V
    /// answers agree with half and a quarter of the step by the convergence criteria (seeds 1-3:
    /// drops within 0.29 s, rises within 0.1 s, fluctuations within 1.4 points; README,
    /// "Convergence"). Half the cost of 1.25 ms, the default before: that was chosen on the
    /// prescribed arm, whose shampoo fluctuation moved 8 points at 2.5 ms; with the servoed arm it
    /// moves 0.7. A numerical choice, not a calibration knob.
    pub timestep_s: f64,
    /// Integrator. `implicitfast`: the creep dashpot (thousands of N s/m on a 1 g node) and the servos'
    /// `kv` are integrated implicitly, which explicit Euler would not survive at this step.
    pub integrator: Integrator,
    /// Friction cone. `elliptic`: exact Coulomb limit (pyramidal creeps, docs/facts.md#mujoco-pyramidal-cones-creep).
    pub cone: Cone,
    /// Ratio of frictional to normal constraint impedance. 3: the pinch test's smallest holding
    /// force is the analytic one (tests/physics_validation.rs; measured with 20 ms contacts at 5 ms,
    /// −0.1 %, and with the default 5 ms contacts at 1.25 ms, +0.02 %); 10, chosen earlier with 10 ms
    /// contacts to stop a held object creeping, needed 24 % more force there at 5 ms.
    pub impratio: f64,
    /// Constraint solver. `newton`: converges in a few iterations to the tolerance below (the
    /// convergence study's answers were measured with it); `cg` and `pgs` trade iterations for
    /// cheaper ones, a numerical choice the speed-accuracy chart can weigh.
    pub solver: Solver,
    /// Solver iterations (upper bound; Newton usually converges in 2-5).
    pub iterations: u32,
    /// Solver tolerance (relative cost improvement). 1e-8: friction converged; tighter costs time for
    /// no measurable change in the validation results, and in the six Section V runs 1e-9 and 1e-10
    /// move no drop by more than 0.3 s and no fluctuation by more than 1 point, where 1e-6 moves the
    /// shampoo's drop by 2 s (docs/studies/convergence.md#the-solvers-settings).
    pub tolerance: f64,
    /// Line-search iterations of the Newton solver. 20: with 5 the object sank 14 mm into the table
    /// during a grasp (measured).
    pub ls_iterations: u32,
    /// Post-solve no-slip iterations. 0: the stiff 5 ms contacts already hold the pinch test's box at
    /// its analytic force (+0.02 %) and stop the slope test's creep. Noslip is a projection applied after
    /// the step, and its answers moved with the step: with 10 iterations and 20 ms contacts the
    /// crimper's fluctuation with feedback went 14 -> 49 -> 68 % at 5 / 2.5 / 1.25 ms
    /// (docs/studies/convergence.md#what-moves-the-answers-mujocos-noslip-pass). Soft 20 ms contacts need it (at 5 ms, 0 iterations left the pinch force
    /// 6-8 % above m(g+a)/2mu).
    pub noslip_iterations: u32,
    /// No-slip solver tolerance.
    pub noslip_tolerance: f64,
    /// Contact solref time constant \[s\] (global default): stiffness of contacts. 7.5 ms: stiff
    /// enough that soft-contact creep does not let a held object slide without noslip (the slope
    /// and pinch tests in tests/physics_validation.rs pass with noslip off), and three steps at the
    /// 2.5 ms default. With the half-link clamp (`finger.base_joint`) two steps (5 ms, MuJoCo's
    /// least: a shorter one is stretched to two) let the pinch's contact ring for one sample as
    /// the crimper's weight comes on (its fluctuation with feedback 12.4-20.1 % over seeds 1-10,
    /// against 12.6-14.9 % at a 1.25 ms step); three give 13.1-14.4 % and move no drop without
    /// feedback by more than 0.17 s (models/README.md). A numerical stiffness of the soft-contact
    /// model, not a material property: at 1.25 and 0.625 ms (six and twelve steps) the Section V
    /// answers are the default's.
    pub contact_timeconst_s: f64,
    /// Contact solref damping ratio (1 = critical).
    pub contact_dampratio: f64,
    /// Contact solimp (d0, dwidth, width \[m\]): impedance 0.95 -> 0.99 over 1 mm of penetration.
    pub contact_solimp: [f64; 3],
    /// Arm simulation mode (`kinematic` | `dynamic`). Not set: `dynamic` on MuJoCo, `kinematic` on
    /// rapier ([`Backend::default_arm_mode`]; the scenario loader fills it in, so summaries record
    /// the mode a run used).
    pub arm_mode: ArmMode,
    /// The largest joint speed the commanded targets are followed with [rad/s] (the prescribed
    /// arm's speed, the servos' setpoints'); UR5e maximum 180 deg/s (docs/facts.md#ur5e-joint-speed). Targets further
    /// away are approached at this speed.
    pub arm_max_speed_rad_s: f64,
    /// Divergence bound: deepest allowed contact penetration \[m\]. 30 mm: a dropped object falls
    /// through the finger or onto the table at up to ~1.5 m/s (a 12 cm fall), and soft contacts let it
    /// in by about v × their time constant before pushing it out (30 mm with 20 ms contacts; a 5 mm
    /// bound turned such drops into "physics failed" errors). A blown-up simulation still goes far
    /// past 30 mm. A produce item's contacts may go deeper where its calibrated contact lets a
    /// 1.5 m/s drop in further (`v / √stiffness`: the basil bunch 0.12 m, docs/studies/produce.md).
    pub max_penetration_m: f64,
    /// Divergence bound: largest allowed kinetic energy of the scene \[J\]. The cell's moving parts hold
    /// < 5 J at UR5e speeds (20 kg arm at 0.5 m/s); 200 J means runaway.
    pub max_kinetic_energy_j: f64,
    /// The rapier backend's own settings (`[physics.rapier]`).
    pub rapier: RapierConfig,
}

impl PhysicsConfig {
    /// The defaults on `backend`, with the arm mode a scenario naming only that backend gets
    /// ([`Backend::default_arm_mode`]); for configurations built in code rather than loaded.
    pub fn on(backend: Backend) -> PhysicsConfig {
        PhysicsConfig { backend, arm_mode: backend.default_arm_mode(), ..PhysicsConfig::default() }
    }
}

impl Default for PhysicsConfig {
    fn default() -> Self {
        PhysicsConfig {
            backend: Backend::Mujoco,
            timestep_s: 0.0025,
            integrator: Integrator::Implicitfast,
            cone: Cone::Elliptic,
            impratio: 3.0,
            solver: Solver::Newton,
            iterations: 50,
            tolerance: 1e-8,
            ls_iterations: 20,
            noslip_iterations: 0,
            noslip_tolerance: 1e-8,
            contact_timeconst_s: 0.0075,
            contact_dampratio: 1.0,
            contact_solimp: [0.95, 0.99, 0.001],
            arm_mode: Backend::Mujoco.default_arm_mode(),
            arm_max_speed_rad_s: std::f64::consts::PI,
            max_penetration_m: 0.03,
            max_kinetic_energy_j: 200.0,
            rapier: RapierConfig::default(),
            models_dir: None,
        }
    }
}

impl Validate for PhysicsConfig {
    fn validate(&self, at: &mut Checker) {
        at.in_range("timestep_s", self.timestep_s, 1e-5, 0.05);
        at.in_range("impratio", self.impratio, 1.0, 1000.0);
        // Solver iterations: MuJoCo's default is 100 (50 line search); 10 000 already costs seconds
        // per step on this scene, more only hangs a run.
        at.require("iterations", (1..=10_000).contains(&self.iterations), || {
            format!("must be between 1 and 10000, got {}", self.iterations)
        });
        at.in_range("tolerance", self.tolerance, 1e-300, 1.0);
        at.require("ls_iterations", (1..=10_000).contains(&self.ls_iterations), || {
            format!("must be between 1 and 10000, got {}", self.ls_iterations)
        });
        at.in_range("noslip_tolerance", self.noslip_tolerance, 0.0, 1.0);
        // A contact slower than 10 s would let objects sink through the table before it acts.
        at.in_range("contact_timeconst_s", self.contact_timeconst_s, 1e-6, 10.0);
        // Damping ratio: 1 is critical; 100 is already a contact that never rebounds.
        at.in_range("contact_dampratio", self.contact_dampratio, 1e-3, 100.0);
        let [d0, dw, w] = self.contact_solimp;
        at.require("contact_solimp", (0.0..1.0).contains(&d0) && (d0..1.0).contains(&dw) && w > 0.0, || {
            format!("needs 0 <= d0 <= dwidth < 1 and width > 0, got {:?}", self.contact_solimp)
        });
        // The UR5e's joints reach π rad/s (180 °/s, docs/facts.md#ur5e-joint-speed); 10 rad/s leaves a margin.
        at.in_range("arm_max_speed_rad_s", self.arm_max_speed_rad_s, 1e-3, 10.0);
        // Divergence guards: a penetration of 10 cm is deeper than the objects are wide, and
        // 1 MJ is a car at highway speed; larger guards never trip.
        at.in_range("max_penetration_m", self.max_penetration_m, 1e-6, 0.1);
        at.in_range("max_kinetic_energy_j", self.max_kinetic_energy_j, 1e-6, 1e6);
        at.section("rapier", &self.rapier);
        at.require("arm_mode", !(self.backend == Backend::Rapier && self.arm_mode == ArmMode::Dynamic), || {
            "the dynamic arm (UR5e servos) is MuJoCo-only; the rapier backend prescribes the arm's motion: \
             set arm_mode = \"kinematic\" or leave it out"
                .into()
        });
    }
}

/// How much strip the joint at the strip's base stands for (`finger.base_joint`): the
/// discretisation's clamp.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BaseJoint {
    /// The whole first link: the joint's stiffness is `EI / l` for the first link's length `l`.
    WholeLink,
    /// The half of the first link beside the clamp (the Hencky bar-chain's): `2 EI / l`.
    HalfLink,
}

/// `[finger]`: the grow-and-twine finger's physical parameters (models/finger.xml is the template).
///
/// Nothing about the real finger's dimensions is published (docs/facts.md#gripper-dimensions-are-unpublished); the values are plausible
/// choices for a flat TPU strip with a tendon, stated here, and the viscoelastic ones are meant to be
/// tuned so the twin reproduces the paper's slip times without feedback (crimper ~10 s, shampoo ~13 s,
/// hammer ~17 s after the arm starts moving).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct FingerConfig {
    /// Number of strip segments (discretisation; the pad's casing and the tip's anchor are single
    /// rigid pieces at any number, `strip::layout`). 7, with `base_refinement` 8: 20 mm links
    /// from the pad to the tip and 2.5 mm links from the strip's base to the pad, 28 bodies in all.
    /// With the clamp at half a link (`base_joint`) its answers agree with links x2 and with a
    /// quarter of the step by every one of the 90 convergence criteria, against the 0.625 ms
    /// reference and against the 0.156 ms one; 21 and 24 links broke 2 and 5 of them
    /// (models/README.md, "Where the pinch's first order came from"; `docs/convergence/`). An
    /// object much smaller than the paper's (a wrap of under ~4 links per turn) should be checked
    /// at links x2 (`tendril chart convergence --quick`). A numerical choice, not a calibration
    /// knob.
    pub segments: u32,
    /// How many times finer than `segments` implies the links are between the strip's base and the
    /// pad's casing (1: a uniform grid). A numerical choice, like `segments`: that stretch holds the
    /// pinch between palm and strip where the wrap starts, which carries most of an object held
    /// without feedback and converges only at first order in the link length there with the
    /// whole-link clamp (`base_joint`; models/README.md, "What still moves with the links"), so it
    /// got the 2.2 mm links the uniform finger needed there; with the half-link clamp it still
    /// needs them (2.5 mm at the default), because the strip's first 20 mm bends by about 30 rad/m
    /// (`fine_from_m`), while the distal stretch, whose loads change slowly, keeps coarse ones.
    /// Doubling `segments` halves both grids.
    pub base_refinement: u32,
    /// Arc length from the strip's base where the fine grid of `base_refinement` starts \[m\]; the
    /// strip below it keeps the coarse links of `segments`. 0 (the default): the fine grid runs
    /// from the base to the pad. A numerical choice, like `base_refinement`, and one that does
    /// not pay on the paper's objects: nothing touches their strip's first 22 mm, but it bends
    /// there by about 30 rad/m, and coarse links there (from 17.5 mm, or 8.75 mm links below it)
    /// moved every drop by 1.2-3.3 s (docs/studies/levers.md, lever 2). Check any other value with
    /// `tendril chart convergence --quick --set finger.fine_from_m=...`.
    pub fine_from_m: f64,
    /// How much strip the joint at the strip's base (the guide's exit, where the grown strip is
    /// clamped) stands for: `"half_link"` (the default: the Hencky bar-chain's clamp, the half of
    /// the first link beside it, so it gets `2 EI / l`) or `"whole_link"` (the default before: the
    /// whole first link, so that joint is half as stiff as the next ones for the same length). A
    /// numerical choice of the discretisation. `"whole_link"` adds a compliance of half a link at
    /// the clamp, an error of first order in the base links' length, and that was the pinch's
    /// first-order error. With `"half_link"` links ×2 moves the three drops without feedback by
    /// 0.01-0.08 s (seeds 1-3), with `"whole_link"` by 0.27-0.41 s (the crimper's 10.14 s to
    /// 9.82 s; models/README.md, "Where the pinch's first order came from").
    pub base_joint: BaseJoint,
    /// Strip length that can be grown out of the guide \[m\]; paper Sec. V grows 14.0 cm.
    pub length_m: f64,
    /// Strip thickness \[m\] (capsule diameter). 2 mm: a choice for a TPU strip with a tendon channel.
    pub thickness_m: f64,
    /// Strip width \[m\] (mass only; the capsules touch along a line). 20 mm, from the photos' proportions.
    pub width_m: f64,
    /// Strip density [kg/m^3]. TPU 1200 (typical datasheet value).
    pub density_kg_m3: f64,
    /// Bending stiffness EI of the strip [N m^2]; each joint gets EI / segment length [N m/rad].
    /// TPU (E ~ 30 MPa) 20 mm x 2 mm strip gives 4e-4. Tuned: 4e-4 (the full section; 2e-4, halved
    /// for the tendon channel, was the earlier guess), so that, as in the paper, the force while the
    /// arm moves stays within 40 % of the setpoint: with 2e-4 the softer strip let the handle rock in
    /// the wrap when its weight came on at lift-off and the pad chattered between 0 and 1 N (70-95 %
    /// of the crimper's setpoint); with 4e-4 the largest deviation is 8-28 %.
    pub bending_stiffness_n_m2: f64,
    /// Bending damping of the strip per unit length, the material's viscous (Kelvin-Voigt) part of
    /// EI [N m^2 s]; each joint gets it / segment length [N m s/rad], as the stiffness does, so the
    /// strip's damping does not change with the number of links. As a time constant, damping / EI.
    /// TPU is a lossy elastomer (loss factor 0.1-0.3 at 1-10 Hz at room temperature, typical of
    /// Shore 85-95A grades); see `bending_armature_kg_m3` for why the value is set near critical.
    pub bending_damping_n_m2_s: f64,
    /// Inertia against bending, per unit length, as the stiffness is: a_joint = this / segment
    /// length [kg m^3 -> kg m^2], so the kinetic energy 1/2 sum a_i (dθ_i/dt)^2 is the continuum
    /// 1/2 ∫ this (dκ/dt)^2 ds at any number of links (κ curvature, s arc length).
    /// Numerical, not physical: MuJoCo's soft contacts are as stiff as the effective mass behind
    /// them, and a bare 1 g segment sank up to 12 mm into the objects at 5 ms. Why this scaling:
    /// a contact at arc length s on an armature-dominated chain sees the inverse effective mass
    /// Σ_i d_i² / a_i over the joints between it and the root (d_i: lever arm); with a_i = c / l
    /// that sum is Σ (k l)² l / c ≈ s³ / (3 c), the same at any link length l, so the contacts' stiffness
    /// does not change with the discretisation. The earlier cubic scaling (a = c' l³, same mass per
    /// segment) gave s³ / (3 c' l⁴): at 64 links the wrap's contacts were 4096 times softer than at
    /// 8 and the objects slid out at the lift. 1.75e-6 kg m^3 is 1e-4 kg m^2 per joint at 8 links
    /// (17.5 mm), the value that kept penetration near 1 mm there. With the bending stiffness it
    /// sets one frequency for every bending mode, sqrt(EI / this) = 15 rad/s.
    pub bending_armature_kg_m3: f64,
    /// Tendon offset from the strip's neutral axis \[m\] (moment arm of the tendon on each joint). 3 mm.
    pub moment_arm_m: f64,
    /// How fast the tendon's tension falls along the strip through friction in its channel [1/m]:
    /// T(s) = T0 exp(-this * s) at arc length s from the base, so each joint's moment arm in the
    /// tendon is `moment_arm_m * exp(-this * s_joint)`. A capstan law in arc length: channel
    /// friction μ on a wrap of radius R gives this = μ / R. 0: no friction (the bending moment is the
    /// same everywhere, and the strip presses the object only where the wrap starts, at the pad and
    /// at the tip). 25 /m: μ ≈ 0.34 on the 13.5 mm radius of the strip around a 12.5 mm handle, a
    /// stated choice for a polymer tendon in a printed TPU channel (polymer on TPU, 0.3-0.5). With
    /// it the strip presses along the whole wrap, as a falling moment must (p = -d²M/ds² where it
    /// conforms), and the pad's force converges with the links (quasi-static wrap, 25 mm of tendon:
    /// 2.22 / 2.17 / 2.18 / 2.22 N at 16 / 32 / 64 / 128 links); without it the pad sat where the wrap
    /// lifts off and touched with its casing's edge (0.5 / 1.7 / 1.8 / 2.3 N). models/README.md,
    /// "The finger as a discretised strip".
    pub tendon_tension_decay_per_m: f64,
    /// Instantaneous tendon-path stiffness K [N/m] (both SLS branches in parallel): tendon plus the soft
    /// material it pulls on; sets how fast grip grows with twine. Tuned: 6000, so that the paper's Kp
    /// brings the pad to 90 % of the setpoint within 5 s (1.1-1.5 s on the three objects): with 3000
    /// the creep of the wound tendon took the motor's whole proportional speed and the crimper's and
    /// the shampoo's estimates settled 8-10 % below the setpoint.
    pub tendon_stiffness_n_m: f64,
    /// Relaxed fraction f of the standard linear solid: after creep the stiffness is f K [-].
    /// Tuned, with `relaxation_time_s`, so that with the motor frozen at the lift the grip decays
    /// until friction no longer carries the object at ≈ 10 / 13 / 17 s after the arm starts
    /// (crimper / shampoo / hammer), as in the paper (Sec. V-C). 0.05: nearly all of the wound-in
    /// tension sits in the creeping branch, as in a soft TPU path whose tendon slides in its channel
    /// (TPU relaxes 30-60 % in minutes at room temperature; the channel friction adds the rest).
    pub relaxed_fraction: f64,
    /// Relaxation time tau \[s\] of the standard linear solid (dashpot c = tau (1 - f) K).
    /// Tuned so that, as in the paper, the three objects drop ≈ 10, 13 and 17 s after the arm
    /// starts: 19 s, with the objects' friction margins, turns the decay of the frozen grip into those
    /// drop times on the converged finger (9.8-10.0 / 13.5 / 17.3 s, seeds 1-3). models/README.md
    /// has the figures: 18 s, the value with the whole-link clamp, dropped the half-link finger
    /// 0.3-1.0 s early; 20 s put the hammer's drop late in the lowering and 22 s let it survive;
    /// 15 s, the value on the coarser 32-link finger, dropped all three 1.6-2.0 s early at 64
    /// links. Seconds to tens of seconds is the usual range of TPU stress relaxation.
    pub relaxation_time_s: f64,
    /// Equivalent translating inertia of each MX-106 at its output \[kg\] (joint armature). A choice.
    pub motor_armature_kg: f64,
    /// Position-servo stiffness of both motors [N/m]. A choice: 1 mm error -> 20 N.
    pub motor_kp_n_m: f64,
    /// Position-servo damping of both motors [N s/m]; near critical for the armature.
    pub motor_kv_n_s_m: f64,
    /// Largest speed of either motor's output [m/s]: commands further away are approached at this
    /// speed. MX-106 no-load speed 45 rpm at 12 V (docs/facts.md#mx-106-speed-and-torque) on the 10 mm spool = 0.047 m/s.
    pub motor_max_speed_m_s: f64,
    /// Largest twine (tendon wound in) \[m\].
    pub twine_max_m: f64,
    /// Distance of the sensor pad's centre from the strip's base \[m\] (on the sleeve, near the guide,
    /// paper Sec. V). 61.25 mm (a choice kept from the first calibration): near the end of the first
    /// turn around a 12-14 mm radius handle, where the pad takes 15-30 % of the strip's normal force
    /// (nearer the base, where the wrap starts, it took 50-60 %, more than the paper's setpoints allow
    /// on its objects). The pad's casing is one rigid piece wherever it sits (`strip::layout`).
    pub pad_position_m: f64,
    /// Rise of the strip per metre along it (dimensionless): the real strip twines as a helix, so its
    /// second turn lies above the first instead of wedging between the first turn and the object.
    /// Modelled as a step of `helix_slope * segment length` between segments (towards the flange).
    /// 0.27: one turn around a 13 mm radius handle (82 mm of strip) rises by the strip's width plus 2 mm.
    pub helix_slope: f64,
    /// Height of the pad's bump tip above the strip's inner face \[m\]. The casing is 4 mm tall and the
    /// bump 1.5 mm (5.5 mm in all); how deep the casing sits in the sleeve is not published, and this
    /// sets how much of the wrap's force the pad takes.
    /// 5.5 mm: the casing stands on the sleeve, not recessed (4 mm casing, Sec. II-A, plus the
    /// assumed 1.5 mm bump); with the tendon's friction (`tendon_tension_decay_per_m`) the pad then
    /// takes 15-30 % of the strip's normal force on the crimper, as the paper's setpoints need.
    pub pad_protrusion_m: f64,
    /// Distance below the flange at which the strip leaves the guide \[m\] (hand length). A choice.
    pub exit_z_m: f64,
}

impl Default for FingerConfig {
    fn default() -> Self {
        FingerConfig {
            segments: 7,
            base_refinement: 8,
            fine_from_m: 0.0,
            base_joint: BaseJoint::HalfLink,
            length_m: 0.14,
            thickness_m: 0.002,
            width_m: 0.02,
            density_kg_m3: 1200.0,
            bending_stiffness_n_m2: 4e-4,
            bending_damping_n_m2_s: 3.5e-6,
            bending_armature_kg_m3: 1.75e-6,
            moment_arm_m: 0.003,
            tendon_tension_decay_per_m: 25.0,
            tendon_stiffness_n_m: 6000.0,
            relaxed_fraction: 0.05,
            relaxation_time_s: 19.0,
            motor_armature_kg: 2.0,
            motor_kp_n_m: 20000.0,
            motor_kv_n_s_m: 400.0,
            motor_max_speed_m_s: 0.047,
            twine_max_m: 0.06,
            pad_position_m: 0.06125,
            pad_protrusion_m: 0.0055,
            helix_slope: 0.27,
            exit_z_m: 0.1,
        }
    }
}

impl FingerConfig {
    /// Length of one segment \[m\].
    pub fn segment_length_m(&self) -> f64 {
        self.length_m / f64::from(self.segments.max(1))
    }
}

impl Validate for FingerConfig {
    fn validate(&self, at: &mut Checker) {
        // 256: 0.55 mm segments on a 14 cm strip, a quarter of the strip's 2 mm thickness; nothing
        // finer describes the strip better (the convergence study's finest uniform finger).
        at.require("segments", (2..=256).contains(&self.segments), || {
            format!("must be between 2 and 256, got {}", self.segments)
        });
        // 8: at the default 8 links the base stretch's links are then 2.2 mm, the uniform finger's
        // converged length; more than 8 would only matter at fewer than 8 links.
        at.require("base_refinement", (1..=8).contains(&self.base_refinement), || {
            format!("must be between 1 and 8, got {}", self.base_refinement)
        });
        // 512: base links of 0.27 mm, an eighth of the strip's thickness (and about 230 bodies in the
        // base stretch alone); finer only slows the run down.
        let base_links = self.segments.saturating_mul(self.base_refinement);
        at.require("base_refinement", base_links <= 512, || {
            format!(
                "segments x base_refinement must be at most 512 (base links of 0.27 mm), got {} x {} = {base_links}; \
                 for a uniform finger of {} links set base_refinement = 1",
                self.segments, self.base_refinement, self.segments
            )
        });
        at.in_range("length_m", self.length_m, 0.02, 0.5);
        // The fine grid must keep at least its first link before the pad's casing.
        at.require("fine_from_m", self.fine_from_m >= 0.0 && self.fine_from_m < self.pad_position_m - 0.006, || {
            format!(
                "must be at least 0 and before the pad's casing (pad_position_m - 0.006 = {} m), got {}",
                self.pad_position_m - 0.006,
                self.fine_from_m
            )
        });
        at.in_range("thickness_m", self.thickness_m, 2e-4, 0.02);
        at.positive("width_m", self.width_m);
        at.positive("density_kg_m3", self.density_kg_m3);
        at.non_negative("bending_stiffness_n_m2", self.bending_stiffness_n_m2);
        at.non_negative("bending_damping_n_m2_s", self.bending_damping_n_m2_s);
        at.non_negative("bending_armature_kg_m3", self.bending_armature_kg_m3);
        at.positive("moment_arm_m", self.moment_arm_m);
        // 100 /m: the tension falls to e^-14 over the 14 cm strip; more leaves the tip unbent.
        at.in_range("tendon_tension_decay_per_m", self.tendon_tension_decay_per_m, 0.0, 100.0);
        at.positive("tendon_stiffness_n_m", self.tendon_stiffness_n_m);
        at.in_range("relaxed_fraction", self.relaxed_fraction, 0.0, 1.0);
        at.positive("relaxation_time_s", self.relaxation_time_s);
        at.positive("motor_armature_kg", self.motor_armature_kg);
        at.positive("motor_kp_n_m", self.motor_kp_n_m);
        at.non_negative("motor_kv_n_s_m", self.motor_kv_n_s_m);
        at.positive("motor_max_speed_m_s", self.motor_max_speed_m_s);
        at.positive("twine_max_m", self.twine_max_m);
        at.require(
            "pad_position_m",
            self.pad_position_m > 0.006 && self.pad_position_m < self.length_m - 0.006,
            || {
                format!(
                    "must leave the 12 mm pad on the strip (0.006 .. length_m - 0.006), got {}",
                    self.pad_position_m
                )
            },
        );
        at.in_range("pad_protrusion_m", self.pad_protrusion_m, 0.0005, 0.0055);
        at.in_range("helix_slope", self.helix_slope, 0.0, 1.0);
        at.positive("exit_z_m", self.exit_z_m);
    }
}

/// Which of the paper's objects the scene holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ObjectName {
    /// Crimper with rubber handle, 351 g.
    Crimper,
    /// Wooden hammer, 419 g.
    Hammer,
    /// Plastic shampoo bottle, 222 g.
    Shampoo,
}

impl std::fmt::Display for ObjectName {
    /// The name as written in scenarios (`crimper`, `hammer`, `shampoo`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ObjectName::Crimper => "crimper",
            ObjectName::Hammer => "hammer",
            ObjectName::Shampoo => "shampoo",
        })
    }
}

impl ObjectName {
    /// The MJCF text of the object (models/objects/*.xml).
    pub fn mjcf(self) -> &'static str {
        match self {
            ObjectName::Crimper => include_str!("../../../../models/objects/crimper.xml"),
            ObjectName::Hammer => include_str!("../../../../models/objects/hammer.xml"),
            ObjectName::Shampoo => include_str!("../../../../models/objects/shampoo.xml"),
        }
    }
}

/// `[object]`: which object, where it stands, and optional overrides.
///
/// The object is a model file (see [`super::object`] for the contract it keeps): `file`, a path
/// relative to the scenario file, or `name`, a shipped object found at run time as
/// `models/objects/<name>.xml` beside the scenarios' folder (the three paper objects are also built
/// into the binary, so it runs on its own). One of the two is required.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectConfig {
    /// A shipped object (`crimper` | `hammer` | `shampoo`, or any `models/objects/<name>.xml`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// An object model file (MJCF), relative to the scenario file; wins over `name`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// Sliding friction of the object against the finger, replacing the model's value on the grip
    /// (`object_grip`, the only part the finger and palm touch; the base keeps its table friction).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Where the object's footprint centre stands on the table, world x and y \[m\]. `None`: right under
    /// the gripper's wrap in the start pose (the scene starts at the grasp).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_m: Option<[f64; 2]>,
    /// The object's mass \[kg\], replacing the model's; its inertia is scaled with it (same shape,
    /// same mass distribution).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Turn of the object about the vertical before the grasp \[deg\] (0: as in its file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yaw_deg: Option<f64>,
}

impl Default for ObjectConfig {
    /// The crimper, as in its file.
    fn default() -> Self {
        ObjectConfig::named(ObjectName::Crimper)
    }
}

impl ObjectConfig {
    /// A shipped object, as in its file.
    pub fn named(name: ObjectName) -> ObjectConfig {
        ObjectConfig {
            name: Some(name.to_string()),
            file: None,
            friction: None,
            position_m: None,
            mass_kg: None,
            yaw_deg: None,
        }
    }

    /// What names the object in summaries: `name`, else the file's stem.
    pub fn label(&self) -> String {
        match (&self.name, &self.file) {
            (Some(n), _) => n.clone(),
            (None, Some(f)) => f.file_stem().map_or_else(|| f.display().to_string(), |s| s.to_string_lossy().into()),
            (None, None) => String::new(),
        }
    }

    /// The object's model: `file` read now (edits take effect without a rebuild), else the shipped
    /// object `name` built into the binary.
    pub fn model(&self) -> Result<super::object::ObjectModel, super::PhysicsError> {
        use super::object::ObjectModel;
        match (&self.file, &self.name) {
            (Some(file), _) => {
                let source = file.display().to_string();
                let text = std::fs::read_to_string(file).map_err(|e| super::PhysicsError::Object {
                    file: source.clone(),
                    what: format!("cannot read: {e}"),
                })?;
                ObjectModel::from_mjcf_in(&source, &text, file.parent())
            }
            (None, Some(name)) => {
                let shipped: ObjectName =
                    name.parse().map_err(|what| super::PhysicsError::Object { file: name.clone(), what })?;
                ObjectModel::from_mjcf(name, shipped.mjcf())
            }
            (None, None) => Err(super::PhysicsError::Object {
                file: "(none)".into(),
                what: "[object] needs `name` or `file`".into(),
            }),
        }
    }
}

impl std::str::FromStr for ObjectName {
    type Err = String;

    fn from_str(s: &str) -> Result<ObjectName, String> {
        match s {
            "crimper" => Ok(ObjectName::Crimper),
            "hammer" => Ok(ObjectName::Hammer),
            "shampoo" => Ok(ObjectName::Shampoo),
            other => Err(format!(
                "no shipped object `{other}` (built in: crimper, hammer, shampoo); give `object.file`, or put \
                 models/objects/{other}.xml beside the scenarios' folder"
            )),
        }
    }
}

impl Validate for ObjectConfig {
    fn validate(&self, at: &mut Checker) {
        at.require("name", self.name.is_some() || self.file.is_some(), || {
            "[object] needs `name` (a shipped object) or `file` (an object model, relative to the scenario)".into()
        });
        match (&self.file, &self.name) {
            (Some(file), _) => at.require("file", file.is_file(), || format!("no such file: {}", file.display())),
            (None, Some(name)) => {
                if let Err(reason) = name.parse::<ObjectName>() {
                    at.require("name", false, || reason);
                }
            }
            (None, None) => {}
        }
        if let Some(m) = self.mass_kg {
            // A few grams to what the arm's 5 kg payload and the finger's ~10 N grip could ever carry.
            at.in_range("mass_kg", m, 0.001, 5.0);
        }
        if let Some(yaw) = self.yaw_deg {
            at.in_range("yaw_deg", yaw, -360.0, 360.0);
        }
        if let Some(mu) = self.friction {
            at.in_range("friction", mu, 0.0, 5.0);
        }
        if let Some([x, y]) = self.position_m {
            // The object must stand within the UR5e's 850 mm reach of its base; 1 m leaves the
            // table's edge a margin.
            at.require("position_m", x.is_finite() && y.is_finite() && x.abs() <= 1.0 && y.abs() <= 1.0, || {
                format!("x and y must lie within ±1 m of the arm's base (UR5e reach 0.85 m), got [{x}, {y}]")
            });
        }
    }
}
