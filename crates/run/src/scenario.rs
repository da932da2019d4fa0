//! The pick-and-place scenario: every section a run on the twin needs, in one TOML file.
//!
//! ```toml
//! name = "hammer"
//! setpoint_n = 1.6
//! [object]
//! name = "hammer"
//! ```
//! Everything else has the paper's or the model's documented defaults; see `scenarios/*.toml`.

use super::detector::{Detection, DetectorConfig};
use super::object_table::ObjectTable;
use super::runner::ControlPlan;
use super::summary::{Gains, RunIdentity};
use serde::{Deserialize, Serialize};
use tendril_cell::gripper::GripperConfig;
use tendril_config::{Checker, Validate};
use tendril_control::ControllerConfig;
use tendril_control::slip::SlipConfig;
use tendril_control::task::TaskConfig;
use tendril_drivers::HardwareConfig;
use tendril_fbg::array::ArrayConfig;
use tendril_fbg::estimate::ForceCalibration;
use tendril_fbg::{InterrogatorConfig, SensorConfig};
use tendril_ros2::Ros2Config;
use tendril_twin::disturbance::DisturbanceConfig;
use tendril_twin::physics::{
    FingerConfig, ObjectConfig, PadPlace, PhysicsConfig, ProduceConfig, SceneModel, SceneSpec,
};
use tendril_twin::sim::{EnvironmentConfig, SimCell};
use tendril_twin::wrist::WristConfig;

/// A pick-and-place scenario (`scenarios/crimper.toml`, ...).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PickPlaceScenario {
    /// Scenario name, echoed in summaries.
    pub name: String,
    /// Seed of every random process (sensor noise) [-]; the same seed gives the same trace. Any
    /// `u64` (above `i64::MAX` as a decimal string, see [`tendril_config::seed`]).
    #[serde(
        default = "default_seed",
        deserialize_with = "tendril_config::seed::deserialize",
        serialize_with = "tendril_config::seed::serialize"
    )]
    pub seed: u64,
    /// Contact-force setpoint \[N\] (paper Sec. V-B: crimper 0.6, hammer 1.6, shampoo 0.8).
    pub setpoint_n: f64,
    /// Keep force control on while the arm moves (paper: both modes compared).
    #[serde(default = "default_feedback")]
    pub feedback: bool,
    /// Control loop rate \[Hz\]. 100 Hz: ten interrogator samples per tick, and ample for a loop
    /// whose closed-loop time constant is about 2 s (paper: 90 % within 5 s).
    #[serde(default = "default_rate")]
    pub control_rate_hz: f64,
    /// The object.
    pub object: ObjectConfig,
    /// A produce item's properties within their literature range, its harvest and its flex's
    /// numerics (read when the object is a produce item; docs/guide/objects.md).
    #[serde(default, skip_serializing_if = "ProduceConfig::is_default")]
    pub produce: ProduceConfig,
    /// The force controller: `type` (default `"pid"`) and that type's gains and limits.
    #[serde(default)]
    pub controller: ControllerConfig,
    /// Task poses and timing.
    #[serde(default)]
    pub task: TaskConfig,
    /// Gripper drive train.
    #[serde(default)]
    pub gripper: GripperConfig,
    /// Slip detector.
    #[serde(default)]
    pub slip: SlipConfig,
    /// Calibration used by the estimator (eq. 8).
    #[serde(default)]
    pub estimator: ForceCalibration,
    /// The FBG sensor's physics.
    #[serde(default)]
    pub sensor: SensorConfig,
    /// The interrogator.
    #[serde(default)]
    pub interrogator: InterrogatorConfig,
    /// Further FBG pads along the finger (a sensor array) and what the controller regulates over
    /// them; none by default: the paper's single pad (docs/guide/array.md).
    #[serde(default, skip_serializing_if = "ArrayConfig::is_default")]
    pub array: ArrayConfig,
    /// Temperature at the sensor.
    #[serde(default)]
    pub environment: EnvironmentConfig,
    /// The arm's wrist force sensor on the twin (the load the tool carries).
    #[serde(default)]
    pub wrist: WristConfig,
    /// MuJoCo settings.
    #[serde(default)]
    pub physics: PhysicsConfig,
    /// The finger's physical parameters.
    #[serde(default)]
    pub finger: FingerConfig,
    /// The real devices' settings (motor IDs, bus speed, FBG windows), for `--hardware real` and
    /// `tendril serve`.
    #[serde(default)]
    pub hardware: HardwareConfig,
    /// Disturbances on the twin (a push on the object, a sensor dropout); none by default.
    #[serde(default)]
    pub disturbance: DisturbanceConfig,
    /// How tendril meets a lab's ROS 2 graph: `tendril serve --ros2`, `--hardware ros2` and
    /// `--bag` (docs/cell/ros2.md); the defaults are a Humble lab's.
    #[serde(default, skip_serializing_if = "Ros2Config::is_default")]
    pub ros2: Ros2Config,
    /// A simulated object detector whose class chooses the setpoint and the controller's keys from
    /// a per-object table; none by default (the scenario's own settings).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detector: Option<DetectorConfig>,
}

fn default_seed() -> u64 {
    1
}
fn default_feedback() -> bool {
    true
}
fn default_rate() -> f64 {
    100.0
}

impl Validate for PickPlaceScenario {
    /// The object file and the models folder relative to the scenario file; the backend's
    /// default arm mode filled in, so the recorded scenario names the one the run had.
    fn prepare(table: &mut toml::Table, file: &std::path::Path) {
        super::paths::resolve_models(table, file);
        super::paths::resolve_object(table, file);
        super::paths::resolve_detector_table(table, file);
        super::backend_defaults::fill_backend_defaults(table);
        super::detector::apply(table);
        super::produce_defaults::fill_produce_defaults(table);
    }

    fn validate(&self, at: &mut Checker) {
        at.require("name", !self.name.trim().is_empty(), || "must not be empty".into());
        at.in_range("control_rate_hz", self.control_rate_hz, 1.0, 1000.0);
        // The sections first: a cross-check below that reads a bad value (estimator.range_n = nan)
        // must not be reported on the key that reads it (setpoint_n).
        at.section("object", &self.object);
        at.section("produce", &self.produce);
        at.section("controller", &self.controller);
        at.section("task", &self.task);
        at.section("gripper", &self.gripper);
        at.section("slip", &self.slip);
        at.section("estimator", &self.estimator);
        at.section("sensor", &self.sensor);
        at.section("interrogator", &self.interrogator);
        at.section("environment", &self.environment);
        at.section("wrist", &self.wrist);
        at.section("physics", &self.physics);
        at.section("finger", &self.finger);
        at.section("hardware", &self.hardware);
        at.section("disturbance", &self.disturbance);
        at.section("ros2", &self.ros2);
        if let Some(d) = &self.detector {
            at.section("detector", d);
            super::detector::check(d, &self.object.label(), at);
        }
        at.require(
            "disturbance.push",
            self.disturbance.push.is_none() || self.physics.backend == tendril_twin::physics::Backend::Mujoco,
            || {
                format!(
                    "the {} backend does not apply pushes; use physics.backend = \"mujoco\"",
                    self.physics.backend.name()
                )
            },
        );
        // Above the sensor's range the reading saturates (4.69 N, paper Sec. IV-B).
        at.require("setpoint_n", self.setpoint_n > 0.0 && self.setpoint_n < self.estimator.range_n, || {
            format!("must be > 0 and below the sensor's range {} N, got {}", self.estimator.range_n, self.setpoint_n)
        });
        at.require("control_rate_hz", self.control_rate_hz <= self.interrogator.sample_rate_hz, || {
            format!("must not exceed interrogator.sample_rate_hz ({})", self.interrogator.sample_rate_hz)
        });
        // First contact must be felt below the top of the range, or the close never ends.
        at.require("task.wrap_contact_n", self.task.wrap_contact_n < self.estimator.range_n, || {
            format!("must be below the sensor's range {} N, got {}", self.estimator.range_n, self.task.wrap_contact_n)
        });
        let settled = &self.task.settled_grasp;
        let resolution_n = tendril_control::settle::RESOLUTION_N;
        at.require(
            "task.settled_grasp.band_pct",
            !settled.enabled || settled.band_n(self.setpoint_n) >= resolution_n,
            || {
                format!(
                    "a band of ±{:.2} mN around the {} N setpoint is finer than the sensor's resolution ({} mN, paper \
                 Sec. IV-B): it can never be told from noise",
                    settled.band_n(self.setpoint_n) * 1e3,
                    self.setpoint_n,
                    resolution_n * 1e3
                )
            },
        );
        let tendon_max_m = self.gripper.tendon_pull_m(self.gripper.twine_max_deg.to_radians());
        at.require("gripper.twine_max_deg", tendon_max_m <= self.finger.twine_max_m + 1e-9, || {
            format!(
                "winds {:.1} mm of tendon, more than finger.twine_max_m ({:.1} mm)",
                tendon_max_m * 1e3,
                self.finger.twine_max_m * 1e3
            )
        });
        at.require("task.growth_m", self.task.growth_m <= self.finger.length_m, || {
            format!("must not exceed finger.length_m ({} m)", self.finger.length_m)
        });
        self.check_gratings_in_windows(at);
        // The default layout (no further pad, every threshold at its default) has nothing to check.
        if self.array != ArrayConfig::default() {
            at.section("array", &self.array);
            self.check_array(at);
        }
        // Pad windows given without an array are refused there too.
        self.check_array_windows(at);
    }
}

impl PickPlaceScenario {
    /// The twin this scenario describes, over its compiled scene model.
    pub fn sim_cell(&self, model: std::sync::Arc<SceneModel>) -> SimCell {
        SimCell::new(model, self.sensor.clone(), self.interrogator.clone(), self.gripper, self.environment, self.seed)
            .with_disturbances(self.disturbance.clone())
            .with_wrist(self.wrist)
            .with_array(&self.array, self.hardware.fbg.channel)
    }

    /// The FBG windows must hold the gratings `[sensor]` describes (the twin behind `tendril serve`
    /// reports those; a real sensor should be described by them too): FBG1 from unloaded to the
    /// top of the range (the backbone's shift at `range_n`, above the loading branch's), FBG2 at
    /// its nominal wavelength.
    fn check_gratings_in_windows(&self, at: &mut Checker) {
        let (w, s) = (&self.hardware.fbg, &self.sensor);
        let fbg1_top_nm = s.lambda1_nm + s.backbone_pm(s.range_n) * 1e-3;
        at.require("hardware.fbg.fbg1_min_nm", w.fbg1_min_nm <= s.lambda1_nm, || {
            format!("must not exceed sensor.lambda1_nm ({} nm), FBG1 unloaded", s.lambda1_nm)
        });
        at.require("hardware.fbg.fbg1_max_nm", !fbg1_top_nm.is_finite() || fbg1_top_nm < w.fbg1_max_nm, || {
            format!(
                "must exceed {fbg1_top_nm:.2} nm, FBG1 at the top of the sensor's range (sensor.lambda1_nm + the strain shift at sensor.range_n)"
            )
        });
        at.require("hardware.fbg.fbg2_min_nm", (w.fbg2_min_nm..w.fbg2_max_nm).contains(&s.lambda2_nm), || {
            format!(
                "the FBG2 window [{}, {}) nm must hold sensor.lambda2_nm ({} nm)",
                w.fbg2_min_nm, w.fbg2_max_nm, s.lambda2_nm
            )
        });
    }

    /// A sensor array's pads must sit on the strip without touching one another or the tip's
    /// anchor, and its gratings must be told apart by the interrogator
    /// ([`ArrayConfig::multiplexing_faults`]).
    fn check_array(&self, at: &mut Checker) {
        use tendril_twin::physics::strip::{PAD_HALF_LENGTH_M, TIP_LENGTH_M};
        if self.array.is_single() {
            return;
        }
        let tip = self.finger.length_m - TIP_LENGTH_M.min(self.finger.length_m / 4.0);
        let casing = 2.0 * PAD_HALF_LENGTH_M;
        for (i, p) in self.array.pads.iter().enumerate() {
            let key = format!("array.pads[{i}].arc_m");
            at.require(&key, p.arc_m - PAD_HALF_LENGTH_M >= 0.0 && p.arc_m + PAD_HALF_LENGTH_M <= tip, || {
                format!(
                    "the pad's 12 mm casing must sit on the strip between its base and the tip's anchor \
                     ({PAD_HALF_LENGTH_M} .. {:.4} m), got {}",
                    tip - PAD_HALF_LENGTH_M,
                    p.arc_m
                )
            });
            let others = std::iter::once(("finger.pad_position_m".to_string(), self.finger.pad_position_m)).chain(
                self.array.pads[..i].iter().enumerate().map(|(j, q)| (format!("array.pads[{j}].arc_m"), q.arc_m)),
            );
            for (other, at_m) in others {
                at.require(&key, (p.arc_m - at_m).abs() >= casing - 1e-12, || {
                    format!("the pad's casing overlaps {other}'s ({} m): centres at least 12 mm apart", at_m)
                });
            }
        }
        for (key, reason) in self.array.multiplexing_faults(&self.sensor, self.hardware.fbg.channel) {
            at.require(&key, false, || reason);
        }
    }

    /// The windows the real path reads a sensor array with (`[hardware.fbg]`, and
    /// `[[hardware.fbg.pads]]` as given or derived from `[array]`): one per further pad, each on
    /// its pad's channel holding its grating's range, the windows on a channel disjoint
    /// (`FbgWindows::for_layout`). Windows for pads the scenario does not have are refused too.
    fn check_array_windows(&self, at: &mut Checker) {
        // A layout whose gratings meet is refused by `check_array` already.
        if !self.array.multiplexing_faults(&self.sensor, self.hardware.fbg.channel).is_empty() {
            return;
        }
        if let Err(faults) = self.hardware.fbg.for_layout(&self.array, &self.sensor) {
            for (key, reason) in faults {
                at.require(&key, false, || reason);
            }
        }
    }

    /// The physics scene this scenario needs (arm starting at the task's home pose).
    pub fn scene_spec(&self) -> SceneSpec {
        SceneSpec {
            physics: self.physics.clone(),
            finger: self.finger.clone(),
            object: Some(self.object.clone()),
            extra_pads: self
                .array
                .pads
                .iter()
                .map(|p| PadPlace {
                    arc_m: p.arc_m,
                    protrusion_m: p.protrusion_m.unwrap_or(self.finger.pad_protrusion_m),
                })
                .collect(),
            arm_q0: self.task.home_deg.map(f64::to_radians),
            produce: self.produce.clone(),
        }
    }

    /// What identifies a run of this scenario in its summary.
    pub fn identity(&self, backend: &str) -> RunIdentity {
        RunIdentity {
            scenario: self.name.clone(),
            object: self.object.label(),
            mass_kg: self.object_mass_kg(),
            feedback: self.feedback,
            controller_type: self.controller.type_name().into(),
            // A controller without PID gains reports none (NaN, `null` in the summary).
            gains: self.controller.pid().map_or(Gains { kp: f64::NAN, ki: f64::NAN, kd: f64::NAN }, |c| Gains {
                kp: c.kp,
                ki: c.ki,
                kd: c.kd,
            }),
            setpoint_n: self.setpoint_n,
            seed: self.seed,
            backend: backend.into(),
        }
    }

    /// The object's mass \[kg\]: the override, else the object's model file (NaN only if it does
    /// not load, when no run can start).
    pub fn object_mass_kg(&self) -> f64 {
        self.object.mass_kg.unwrap_or_else(|| self.object.model().map_or(f64::NAN, |m| m.mass_kg))
    }

    /// What the detector reported for this run (`None` without a `[detector]`, or when its table
    /// does not read, which validation refuses): the same draw that chose the run's settings.
    pub fn detection(&self) -> Option<Detection> {
        let d = self.detector.as_ref()?;
        let table = ObjectTable::read(&d.table).ok()?;
        Some(d.draw(self.seed, &self.object.label(), &table.class_names(), table.fallback.is_some()))
    }

    /// What the control side needs.
    pub fn control_plan(&self) -> ControlPlan {
        ControlPlan {
            setpoint_n: self.setpoint_n,
            feedback: self.feedback,
            rate_hz: self.control_rate_hz,
            controller: self.controller.clone(),
            calibration: self.estimator.clone(),
            task: self.task.clone(),
            gripper: self.gripper,
            slip: self.slip,
            object_weight_n: Some(self.object_mass_kg() * tendril_cell::G_M_S2).filter(|w| w.is_finite()),
            array: self.array.clone(),
        }
    }
}
