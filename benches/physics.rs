//! Simulation speed of the physics scenes, reported as time per simulated second: the real-time factor
//! is 1 / (that time in seconds). `cargo bench --bench physics`.
//!
//! - `full_scene_1s`: the pick-and-place scene with default settings (the servoed arm, the default
//!   finger with the pad, crimper, table), already grasped, lifting the hand 5 cm in the measured
//!   second.
//! - `full_scene_guide_walls_kept_1s`: the same with the guide's walls kept in the collision search
//!   (`SceneModel::without_guide_pruning`): what pruning them saves (issue 39, lever 3). Before
//!   timing, the bench checks that both give the same state after the lift, bit for bit.
//! - `full_scene_kinematic_arm_1s`: the same with the arm's motion prescribed.
//! - `full_scene_rapier_32links_5ms_1s`: the prescribed-arm scene on the rapier backend (32 uniform
//!   links, 5 ms; see below).
//! - `minimal_box_on_plane_1s` (and `_rapier_1s`): a box resting on a plane with the same options.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::{Duration, Instant};
use tendril_twin::physics::validation::ValidationRun;
use tendril_twin::physics::{ArmMode, Backend, Physics, PhysicsConfig, SceneModel, SceneSpec, validation};
use tendril_ur5e::kinematics as ur5e;

/// A scene already holding the object: grown (3.5 s at the motor's speed), twined to 32 mm at a steady
/// 7.5 mm/s (4.3 s), settled (0.5 s).
fn grasped(spec: &SceneSpec, keep_walls: bool) -> Box<dyn Physics> {
    let mut model = SceneModel::build(spec).expect("scene builds");
    if keep_walls {
        model = model.without_guide_pruning();
    }
    let mut s = model.start().expect("starts");
    s.set_growth(spec.finger.length_m).unwrap();
    s.run_for(3.5).unwrap();
    let n = (0.032 / 0.0075 / s.timestep()).round() as usize;
    for k in 1..=n {
        s.set_twine(0.032 * k as f64 / n as f64).unwrap();
        s.step().unwrap();
    }
    s.run_for(0.5).unwrap();
    assert!(s.readout().grip_contacts > 0, "bench scene must be grasping");
    s
}

/// Joint targets lifting the hand 5 cm in one second (computed outside the timing).
fn lift_targets(steps: usize) -> Vec<[f64; 6]> {
    let start = ur5e::forward(&ur5e::HOME);
    let mut seed = ur5e::HOME;
    (1..=steps)
        .map(|k| {
            let mut t = start;
            t.translation.vector.z += 0.05 * k as f64 / steps as f64;
            seed = ur5e::inverse_near(&t, &seed).expect("reachable");
            seed
        })
        .collect()
}

/// The state after the grasp and the lift to `targets`.
fn lifted(spec: &SceneSpec, keep_walls: bool, targets: &[[f64; 6]]) -> Option<tendril_twin::frames::Snapshot> {
    let mut s = grasped(spec, keep_walls);
    for q in targets {
        s.set_arm_target(*q).unwrap();
        s.step().unwrap();
    }
    s.snapshot()
}

fn bench_scene(c: &mut Criterion, name: &str, spec: SceneSpec, keep_walls: bool) {
    let steps = (1.0 / spec.physics.timestep_s).round() as usize;
    let targets = lift_targets(steps);
    c.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let mut s = grasped(&spec, keep_walls);
                let t0 = Instant::now();
                for q in &targets {
                    s.set_arm_target(*q).unwrap();
                    s.step().unwrap();
                }
                total += t0.elapsed();
                black_box(s.readout());
            }
            total
        })
    });
}

fn physics(c: &mut Criterion) {
    // The guard: pruning the guide's walls changes no bit of the state (tests/guide_pruning.rs
    // holds whole runs to it); a bench that timed a different trajectory would compare nothing.
    let targets = lift_targets((1.0 / SceneSpec::default().physics.timestep_s).round() as usize);
    let pruned = lifted(&SceneSpec::default(), false, &targets);
    assert!(pruned == lifted(&SceneSpec::default(), true, &targets), "pruning the guide's walls moved the state");
    bench_scene(c, "full_scene_1s", SceneSpec::default(), false);
    bench_scene(c, "full_scene_guide_walls_kept_1s", SceneSpec::default(), true);
    let mut kinematic = SceneSpec::default();
    kinematic.physics.arm_mode = ArmMode::Kinematic;
    bench_scene(c, "full_scene_kinematic_arm_1s", kinematic, false);
    // rapier at 32 uniform links and a 5 ms step, the setting of the rapier comparison (docs/studies/rapier.md): at 64
    // uniform links and 1.25 ms it runs at about 0.1x real time.
    let mut rapier = SceneSpec {
        physics: PhysicsConfig { timestep_s: 0.005, ..PhysicsConfig::on(Backend::Rapier) },
        ..SceneSpec::default()
    };
    rapier.finger.segments = 32;
    rapier.finger.base_refinement = 1;
    bench_scene(c, "full_scene_rapier_32links_5ms_1s", rapier, false);

    for (name, backend) in
        [("minimal_box_on_plane_1s", Backend::Mujoco), ("minimal_box_on_plane_rapier_1s", Backend::Rapier)]
    {
        let p = PhysicsConfig::on(backend);
        let model = std::sync::Arc::new(validation::box_on_plane(&p).expect("builds"));
        c.bench_function(name, |b| {
            b.iter(|| {
                let mut run = ValidationRun::new(model.clone(), &p).expect("starts");
                run.run_for(1.0).expect("steps");
                black_box(run.body_position("box").expect("has a box")[2])
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(Duration::from_secs(3));
    targets = physics
}
criterion_main!(benches);
