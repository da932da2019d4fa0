//! The simulated cell: the physics (MuJoCo or rapier) and the FBG forward model behind [`Cell`].
//!
//! Per tick the control code reads motor angles and the latest interrogator sample and writes
//! motor targets, exactly as on the real cell. In between, [`Cell::wait_until`] steps the physics
//! and samples the sensor model at the interrogator's rate with the pad's true contact force.

use super::disturbance::{DisturbanceConfig, DisturbanceSchedule};
use super::physics::{Physics, PhysicsError, PhysicsReadout, SceneModel};
use super::wrist::{WristConfig, WristSensor};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use tendril_cell::Phase;
use tendril_cell::gripper::GripperConfig;
use tendril_cell::{Cell, CellCommand, CellError, CellState, GroundTruth, Lifecycle, require_state};
use tendril_config::{Checker, Validate};
use tendril_fbg::array::{ArrayConfig, ArrayPeaks};
use tendril_fbg::array_spectrum::ArraySpectra;
use tendril_fbg::signals::Wavelengths;
use tendril_fbg::{FbgSensor, InterrogatorConfig, SensorConfig};

/// The sensor's surroundings (TOML `[environment]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EnvironmentConfig {
    /// Temperature at the sensor when the run starts [°C]: a lab at 25 °C (the paper's room
    /// temperature, Sec. IV-B).
    pub temperature_c: f64,
    /// Temperature drift during the run [°C/s]; 0 in a lab, non-zero to test compensation.
    pub temperature_ramp_c_per_s: f64,
}

impl Default for EnvironmentConfig {
    fn default() -> Self {
        EnvironmentConfig { temperature_c: 25.0, temperature_ramp_c_per_s: 0.0 }
    }
}

impl Validate for EnvironmentConfig {
    fn validate(&self, at: &mut Checker) {
        // The TPU casing is printed at 235 °C and softens far below; the paper tests 25-45 °C.
        at.in_range("temperature_c", self.temperature_c, -20.0, 80.0);
        at.in_range("temperature_ramp_c_per_s", self.temperature_ramp_c_per_s, -1.0, 1.0);
    }
}

impl EnvironmentConfig {
    /// Temperature at cell time `t` [°C].
    pub fn temperature_at(&self, t: f64) -> f64 {
        self.temperature_c + self.temperature_ramp_c_per_s * t
    }
}

/// Twin of the gripping cell: physics (the backend the scene's spec names) + FBG forward model.
pub struct SimCell {
    model: Arc<SceneModel>,
    scene: Option<Box<dyn Physics>>,
    sensor_config: SensorConfig,
    interrogator: InterrogatorConfig,
    sensor: FbgSensor,
    wrist_config: WristConfig,
    wrist: WristSensor,
    gripper: GripperConfig,
    environment: EnvironmentConfig,
    seed: u64,
    lifecycle: Lifecycle,
    latest: Wavelengths,
    /// The further pads of a sensor array ([`SimCell::with_array`]): their sensor models.
    array: Vec<PadSensor>,
    /// Their latest samples.
    latest_array: ArrayPeaks,
    /// In spectral mode, every grating of the array in its channel's one spectrum, and the noise
    /// stream of those spectra (`None`: each pad's peaks drawn on their own, analytic mode).
    spectra: Option<(ArraySpectra, ArraySpectraSource)>,
    next_sample_s: f64,
    /// The physics readout after the last step, read once per tick by `read`, the sensor and
    /// the ground truth alike.
    readout: PhysicsReadout,
    /// The scenario's disturbances (`[disturbance]`), empty by default.
    disturbances: DisturbanceSchedule,
    /// Whether the last sensor sampling delivered a new interrogator sample.
    fresh_sample: bool,
    /// Whether the object force is currently set (so it is cleared once, after the push).
    pushing: bool,
    /// The MuJoCo states recorded for `tendril render` ([`SimCell::record_frames`]).
    frames: Option<crate::frames::FrameRecorder>,
    /// Whether [`Cell::wait_until`] samples the sensor up to the time waited for rather than the
    /// physics' time ([`SimCell::sample_every_wait`]).
    sample_to_wait_time: bool,
    /// Whether the physics counts contacts per geom pair ([`SimCell::count_contacts`]).
    count_contacts: bool,
}

/// What rebuilds the array's spectra for a new run: the layout's windows and the noise seed.
#[derive(Debug, Clone)]
struct ArraySpectraSource {
    windows: Vec<tendril_fbg::array::GratingWindow>,
    rng: ChaCha8Rng,
}

/// The noise seed of the array's spectra: a stream of its own beside every pad's (pad numbers
/// stop at 8, so 1000 is no pad's).
const SPECTRA_STREAM: usize = 1000;

/// A further pad's sensor model, and whether it reads pad 0's reference grating instead of its own.
#[derive(Debug, Clone)]
struct PadSensor {
    config: SensorConfig,
    model: FbgSensor,
    shares_reference: bool,
}

/// The noise seed of further pad `k` (1-based) of a run seeded `seed`: its own stream, so adding a
/// pad leaves every other pad's noise as it was (pad 0 keeps `seed` itself). The step is the
/// 64-bit golden ratio, which spreads consecutive `k` over the whole range.
fn pad_seed(seed: u64, k: usize) -> u64 {
    seed.wrapping_add(0x9E37_79B9_7F4A_7C15_u64.wrapping_mul(k as u64))
}

impl SimCell {
    /// Reads the further pads of `array` besides pad 0 (`[array]`): each its own sensor model
    /// (`sensor` with the pad's wavelengths) and noise stream, sampled at pad 0's instants with
    /// its own contact force. In spectral mode every grating, pad 0's included, is read from its
    /// channel's one spectrum (`tendril_fbg::array_spectrum`), pad 0 on `first_channel`. The scene
    /// must carry the same pads (`SceneSpec::extra_pads`); [`Cell::configure`] refuses it
    /// otherwise.
    pub fn with_array(mut self, array: &ArrayConfig, first_channel: usize) -> SimCell {
        self.spectra =
            (self.interrogator.mode == tendril_fbg::InterrogatorMode::Spectral && !array.is_single()).then(|| {
                let windows = array.windows(&self.sensor_config, first_channel);
                let source =
                    ArraySpectraSource { windows, rng: ChaCha8Rng::seed_from_u64(pad_seed(self.seed, SPECTRA_STREAM)) };
                (ArraySpectra::new(&self.interrogator.spectral, &source.windows), source)
            });
        self.array = (1..=array.pads.len())
            .map(|k| {
                let config = array.pad_sensor(&self.sensor_config, k);
                PadSensor {
                    model: FbgSensor::new(&config, &self.interrogator, pad_seed(self.seed, k)),
                    config,
                    shares_reference: array.pads[k - 1].lambda2_nm.is_none(),
                }
            })
            .collect();
        self.latest_array = ArrayPeaks::filled(self.array.len(), Wavelengths::default());
        self
    }

    /// Commands the growth and twine motors \[rad\] only. The arm's command stays as it is, and with
    /// it the interval over which the kinematic arm moves to its target (the time between two arm
    /// commands): for a caller that updates the motors more often than arm targets arrive, as the
    /// virtual devices do.
    pub fn write_motors(&mut self, growth_motor_rad: f64, twine_motor_rad: f64) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "write")?;
        let growth = self.gripper.growth_length_m(growth_motor_rad);
        let twine = self.gripper.tendon_pull_m(twine_motor_rad);
        let scene = self.scene.as_mut().expect("active implies configured");
        scene.set_growth(growth).map_err(Self::physics_error)?;
        scene.set_twine(twine).map_err(Self::physics_error)?;
        Ok(())
    }

    /// Tendon tension after the last step \[N\] (both branches): the twine motor's load, which
    /// the virtual MX-106 reports as Present Current. 0 before activation.
    pub fn tendon_tension_n(&self) -> f64 {
        self.readout.tendon_tension_n
    }

    /// Radius of the twine spool \[m\]: the lever the tendon tension acts on at the twine motor.
    pub fn twine_spool_radius_m(&self) -> f64 {
        self.gripper.twine_spool_radius_m
    }

    /// Draws the interrogator's samples up to each time [`Cell::wait_until`] is given, holding
    /// the pad force of the last physics step in between, rather than only up to the physics'
    /// own time (which advances a whole step at once). For the virtual interrogator behind `tendril
    /// serve`, whose ticks are shorter than a physics step: every tick one interrogator period long
    /// then brings exactly one new sample. Runs (`tendril run`) do not use it.
    pub fn sample_every_wait(&mut self) {
        self.sample_to_wait_time = true;
    }

    /// The compiled scene model the cell runs on.
    pub fn model(&self) -> &Arc<SceneModel> {
        &self.model
    }

    /// The scene's current state in MuJoCo's layout (what `frames.bin` records and a
    /// renderer draws); `None` before configuration or when the backend keeps no such state.
    pub fn snapshot(&self) -> Option<crate::frames::Snapshot> {
        self.scene.as_ref()?.snapshot()
    }

    /// The run's MuJoCo data (for `tendril view`'s viewer to show and perturb), once configured
    /// and when the backend is MuJoCo.
    pub fn mujoco_data_mut(&mut self) -> Option<&mut mujoco_rs::prelude::MjData<Arc<mujoco_rs::prelude::MjModel>>> {
        self.scene.as_mut()?.mujoco_data_mut()
    }

    /// Knocks the object now (`tendril view`'s key): a push the size of the scenario's
    /// `[disturbance.push]` (or [`super::disturbance::PushConfig::default_knock`]) from the next
    /// physics step on. Returns the cell time of the knock, `None` before configuration.
    pub fn knock(&mut self) -> Option<f64> {
        let t = self.scene.as_ref()?.time();
        self.disturbances.knock(t);
        Some(t)
    }

    /// A cell over a compiled scene model (shareable between runs). Nothing is simulated until
    /// [`Cell::configure`].
    pub fn new(
        model: Arc<SceneModel>,
        sensor: SensorConfig,
        interrogator: InterrogatorConfig,
        gripper: GripperConfig,
        environment: EnvironmentConfig,
        seed: u64,
    ) -> SimCell {
        SimCell {
            sensor: FbgSensor::new(&sensor, &interrogator, seed),
            wrist_config: WristConfig::default(),
            wrist: WristSensor::new(&WristConfig::default(), seed),
            model,
            scene: None,
            sensor_config: sensor,
            interrogator,
            gripper,
            environment,
            seed,
            lifecycle: Lifecycle::Unconfigured,
            latest: Wavelengths { fbg1_nm: 0.0, fbg2_nm: 0.0 },
            array: Vec::new(),
            latest_array: ArrayPeaks::default(),
            spectra: None,
            next_sample_s: 0.0,
            readout: PhysicsReadout::default(),
            disturbances: DisturbanceSchedule::default(),
            fresh_sample: true,
            pushing: false,
            frames: None,
            sample_to_wait_time: false,
            count_contacts: false,
        }
    }

    /// Subjects the run to `disturbances` (`[disturbance]`): a push on the object, a gap in the
    /// interrogator's samples. Phase-relative onsets resolve as the runner reports the phases
    /// ([`Cell::phase_started`]).
    pub fn with_disturbances(mut self, disturbances: DisturbanceConfig) -> SimCell {
        self.disturbances = DisturbanceSchedule::new(disturbances);
        self
    }

    /// Reads the tool's load through a wrist force sensor like `wrist` (`[wrist]`; the default
    /// otherwise).
    pub fn with_wrist(mut self, wrist: WristConfig) -> SimCell {
        self.wrist_config = wrist;
        self.wrist = WristSensor::new(&wrist, self.seed);
        self
    }

    /// Records the scene's MuJoCo state at `fps` frames per second of cell time from activation on
    /// (for `tendril render`); [`SimCell::take_frames`] hands them over.
    /// Reading the state changes nothing in the run.
    pub fn record_frames(&mut self, fps: f64) {
        self.frames = Some(crate::frames::FrameRecorder::new(fps));
    }

    /// Counts the contacts of each geom pair at every physics step of the run (from configuration
    /// on), for [`SimCell::contact_census`]. Counting changes nothing in the run.
    pub fn count_contacts(&mut self) {
        self.count_contacts = true;
        if let Some(scene) = self.scene.as_mut() {
            scene.count_contacts();
        }
    }

    /// The contacts counted so far, if [`SimCell::count_contacts`] was asked for and the backend
    /// counts them (MuJoCo).
    pub fn contact_census(&self) -> Option<crate::physics::ContactCensus> {
        self.scene.as_ref()?.contact_census()
    }

    /// The area of the finger's faces touching the object now \[m²\] (MuJoCo only; see
    /// [`crate::physics::Scene::contact_area_m2`]).
    pub fn contact_area_m2(&self) -> Option<f64> {
        self.scene.as_ref()?.contact_area_m2()
    }

    /// The frames recorded so far, if [`SimCell::record_frames`] was asked for and the backend has
    /// a MuJoCo state.
    pub fn take_frames(&mut self) -> Option<crate::frames::FrameLog> {
        self.frames.as_mut()?.take()
    }

    fn scene(&self) -> &dyn Physics {
        self.scene.as_deref().expect("configured before use: the lifecycle checks guarantee it")
    }

    fn physics_error(e: PhysicsError) -> CellError {
        match e {
            PhysicsError::Diverged { time_s, cause } => CellError::Physics { time_s, cause: cause.to_string() },
            other => CellError::Physics { time_s: f64::NAN, cause: other.to_string() },
        }
    }

    /// Samples the sensor at every interrogator instant up to the scene's time, holding the
    /// contact force of the last physics step (zero-order hold over one step).
    /// With `wait_time` (see [`SimCell::sample_every_wait`]) the sampling runs up to that time.
    fn sample_sensor(&mut self, wait_time: Option<f64>) {
        let dt = 1.0 / self.interrogator.sample_rate_hz;
        self.readout = self.scene().readout();
        let force = self.readout.pad_force_n;
        // Up to the physics' time (to 1e-12 s), or to the time waited for (the physics may have
        // stepped past it: it steps once past the middle of a step): a quarter period's tolerance
        // there keeps the summed sample instants' rounding from skipping or doubling one.
        let until = match wait_time {
            Some(t) if self.sample_to_wait_time => t + 0.25 * dt,
            _ => self.readout.time_s + 1e-12,
        };
        self.fresh_sample = false;
        while self.next_sample_s <= until {
            let temperature = self.environment.temperature_at(self.next_sample_s);
            // The sensor model runs through a dropout (its noise and thermal state advance); only
            // the delivery is lost. The first sample (the activation's) is always delivered.
            let deliver = self.next_sample_s == 0.0 || !self.disturbances.sample_dropped(self.next_sample_s);
            let forces = self.readout.extra_pad_forces_n;
            let (sample, pads) = match self.spectra.as_mut() {
                None => {
                    let sample = self.sensor.sample(force, temperature, dt);
                    let mut pads = ArrayPeaks::filled(self.array.len(), Wavelengths::default());
                    for (k, pad) in self.array.iter_mut().enumerate() {
                        let mut w = pad.model.sample(forces.as_slice()[k], temperature, dt);
                        if pad.shares_reference {
                            w.fbg2_nm = sample.fbg2_nm;
                        }
                        pads.as_mut_slice()[k] = w;
                    }
                    (sample, pads)
                }
                Some((spectra, source)) => {
                    // Every grating's true wavelength, in the layout's windows' order (pad 0's
                    // two, then each further pad's strain grating and its own reference if any).
                    let b0 = self.sensor.bragg(force, temperature, dt);
                    let mut lines = vec![b0.fbg1_nm, b0.fbg2_nm];
                    let mut own = Vec::with_capacity(self.array.len());
                    for (k, pad) in self.array.iter_mut().enumerate() {
                        let b = pad.model.bragg(forces.as_slice()[k], temperature, dt);
                        lines.push(b.fbg1_nm);
                        if !pad.shares_reference {
                            lines.push(b.fbg2_nm);
                        }
                        own.push(!pad.shares_reference);
                    }
                    let found = spectra.detect(&lines, &mut source.rng);
                    let q = |nm: f64| self.sensor.quantize(nm);
                    let sample = Wavelengths { fbg1_nm: q(found[0]), fbg2_nm: q(found[1]) };
                    let mut pads = ArrayPeaks::filled(self.array.len(), Wavelengths::default());
                    let mut at = 2;
                    for (k, &has_own) in own.iter().enumerate() {
                        let fbg1_nm = q(found[at]);
                        let fbg2_nm = if has_own { q(found[at + 1]) } else { sample.fbg2_nm };
                        at += 1 + usize::from(has_own);
                        pads.as_mut_slice()[k] = Wavelengths { fbg1_nm, fbg2_nm };
                    }
                    (sample, pads)
                }
            };
            if deliver {
                self.latest = sample;
                self.latest_array = pads;
                self.fresh_sample = true;
            }
            self.next_sample_s += dt;
        }
    }
}

impl Cell for SimCell {
    fn backend(&self) -> &str {
        self.model.spec().physics.backend.name()
    }

    fn lifecycle(&self) -> Lifecycle {
        self.lifecycle
    }

    fn configure(&mut self) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Unconfigured, "configure")?;
        let mut scene = self.model.start().map_err(Self::physics_error)?;
        if self.count_contacts {
            scene.count_contacts();
        }
        self.scene = Some(scene);
        self.sensor = FbgSensor::new(&self.sensor_config, &self.interrogator, self.seed);
        for (k, pad) in self.array.iter_mut().enumerate() {
            pad.model = FbgSensor::new(&pad.config, &self.interrogator, pad_seed(self.seed, k + 1));
        }
        if let Some((spectra, source)) = self.spectra.as_mut() {
            *spectra = ArraySpectra::new(&self.interrogator.spectral, &source.windows);
            source.rng = ChaCha8Rng::seed_from_u64(pad_seed(self.seed, SPECTRA_STREAM));
        }
        let pads_in_scene = self.model.spec().extra_pads.len();
        if pads_in_scene != self.array.len() {
            return Err(CellError::Configure(format!(
                "the sensor array reads {} further pads, the scene carries {pads_in_scene}",
                self.array.len()
            )));
        }
        self.wrist = WristSensor::new(&self.wrist_config, self.seed);
        self.next_sample_s = 0.0;
        self.disturbances.restart();
        self.pushing = false;
        self.lifecycle = Lifecycle::Inactive;
        Ok(())
    }

    fn activate(&mut self) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Inactive, "activate")?;
        self.lifecycle = Lifecycle::Active;
        self.sample_sensor(None);
        if let (Some(frames), Some(scene)) = (self.frames.as_mut(), self.scene.as_deref()) {
            frames.offer(scene);
        }
        Ok(())
    }

    fn deactivate(&mut self) -> Result<(), CellError> {
        // Idempotent: the runner calls it on every exit path.
        if self.lifecycle == Lifecycle::Active {
            self.lifecycle = Lifecycle::Inactive;
        }
        Ok(())
    }

    fn read(&mut self) -> Result<CellState, CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "read")?;
        let r = &self.readout;
        Ok(CellState {
            time_s: r.time_s,
            arm_q: r.arm_q,
            growth_motor_rad: self.gripper.growth_motor_rad(r.growth_m),
            twine_motor_rad: r.twine_m / self.gripper.twine_spool_radius_m,
            wavelengths: self.latest,
            array: self.latest_array,
            tool_load_n: r
                .tool_load_n
                .filter(|_| self.wrist_config.present)
                .map(|load| self.wrist.read(load, r.time_s)),
        })
    }

    fn write(&mut self, c: &CellCommand) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "write")?;
        let scene = self.scene.as_mut().expect("active implies configured");
        scene.set_arm_target(c.arm_q).map_err(Self::physics_error)?;
        self.write_motors(c.growth_motor_rad, c.twine_motor_rad)
    }

    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "wait")?;
        let scene = self.scene.as_mut().expect("active implies configured");
        let half_step = 0.5 * scene.timestep();
        let push = self.disturbances.has_push();
        while scene.time() < time_s - half_step {
            if push {
                let force = self.disturbances.push_force_n(scene.time(), scene.timestep());
                if force.is_some() || self.pushing {
                    scene.set_object_force(force.unwrap_or([0.0; 3])).map_err(Self::physics_error)?;
                    self.pushing = force.is_some();
                }
            }
            scene.step().map_err(Self::physics_error)?;
            if let Some(frames) = self.frames.as_mut() {
                frames.offer(scene.as_ref());
            }
        }
        self.sample_sensor(Some(time_s));
        Ok(())
    }

    fn phase_started(&mut self, phase: Phase, time_s: f64) {
        self.disturbances.phase_started(phase, time_s);
    }

    fn sample_is_new(&self) -> bool {
        self.fresh_sample
    }

    fn ground_truth(&self) -> Option<GroundTruth> {
        self.scene.as_ref()?;
        let r = &self.readout;
        Some(GroundTruth {
            sensor_force_n: r.pad_force_n,
            array_force_n: r.extra_pad_forces_n,
            grip_force_n: r.grip_force_n,
            object_height_m: r.object_pos_m[2] - self.model.placement().table_z,
            slip_speed_m_s: r.slip_speed_m_s,
            in_contact: r.touching,
            object_in_hand_m: r.object_in_hand_m,
            produce: r.produce.zip(self.model.produce()).map(|(p, part)| {
                let props = &part.item.properties;
                tendril_cell::ProduceTruth {
                    pressure_pa: p.damage.now_peak_pa,
                    area_above_m2: p.damage.now_area_above_m2,
                    peak_pa: p.damage.peak_pa,
                    peak_at: p.damage.peak_at.map_or("", |t| t.name()),
                    max_area_above_m2: p.damage.max_area_above_m2,
                    time_above_s: p.damage.time_above_s,
                    bruise_pa: props.bruise_pa,
                    harvest: p.harvest,
                    stem_tension_n: p.stem_tension_n,
                    max_stem_tension_n: p.max_stem_tension_n,
                    detach_n: props.detach_n,
                    detached_s: p.detached_s,
                    pad_bump_force_n: p.bump_force_n,
                }
            }),
        })
    }
}
