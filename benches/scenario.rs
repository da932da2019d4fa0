//! A full pick-and-place scenario on the twin, start to finish: physics, sensor model, estimator,
//! controller and task sequencing (`cargo bench --bench scenario`).
//!
//! Criterion reports the wall time of one run; the bench also prints simulated seconds per wall
//! second (the goal: ≥ 100× real time on one core).
//!
//! `TENDRIL_BENCH_SET` adds scenario overrides to every run (comma-separated `key=value`), so that
//! another setting is benched in the same sitting as the default, e.g. the whole-link finger:
//! `TENDRIL_BENCH_SET=finger.base_joint=whole_link,finger.segments=8,physics.contact_timeconst_s=0.005,finger.relaxation_time_s=18
//! cargo bench --bench scenario -- mujoco`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;
use std::time::{Duration, Instant};
use tendril_run::execute::{ModelCache, run_on_twin};
use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::physics::Backend;

/// The shipped scenario on `backend`: MuJoCo at the converged default; rapier at 32 uniform links
/// and a 5 ms step, the setting of the rapier comparison (docs/studies/rapier.md) (at 64 uniform
/// links and 1.25 ms it runs at about 0.1x real time). Shortened ([`CHECK_ONLY`]) unless `timed`.
fn scenario(name: &str, backend: Backend, timed: bool) -> PickPlaceScenario {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios").join(format!("{name}.toml"));
    let mut overrides = vec![backend.as_override()];
    if backend == Backend::Rapier {
        overrides.extend(RAPIER_NUMERICS.map(|s| s.parse().expect("valid")));
    }
    if !timed {
        overrides.extend(CHECK_ONLY.map(|s| s.parse().expect("valid")));
    }
    if let Ok(extra) = std::env::var("TENDRIL_BENCH_SET") {
        overrides.extend(
            extra.split(',').filter(|s| !s.is_empty()).map(|s| s.parse().expect("TENDRIL_BENCH_SET: key=value")),
        );
    }
    tendril_config::load(&file, &overrides).expect("shipped scenarios load")
}

/// Rapier's numerics in the rapier comparison (docs/studies/rapier.md), as `tests/backend_rapier.rs`
/// runs them.
const RAPIER_NUMERICS: [&str; 3] = ["finger.segments=32", "finger.base_refinement=1", "physics.timestep_s=0.005"];

/// What `cargo test --all-targets` runs instead of the whole scenario: it only checks that each
/// bench runs (every phase, each backend), so the grasp lasts 1 s and the moves are time-optimal,
/// a pick-and-place of about 16 simulated seconds instead of 43.5. On rapier the whole one takes
/// about 45 s of one core, and `tests/backend_rapier.rs` already runs it to the end, asserted.
const CHECK_ONLY: [&str; 2] = ["task.grasp_s=1", "task.minimum_durations=false"];

fn full_scenario(c: &mut Criterion) {
    let mut group = c.benchmark_group("scenario");
    group.sample_size(10).measurement_time(Duration::from_secs(20));
    let runs = ["crimper", "shampoo", "hammer"].into_iter().flat_map(|n| [(n, Backend::Mujoco), (n, Backend::Rapier)]);
    // `cargo test --all-targets` runs each bench once to check it works ([`CHECK_ONLY`]); the
    // timed runs below are for `cargo bench` (which passes `--bench`) only.
    let timed = std::env::args().any(|a| a == "--bench");
    for (name, backend) in runs {
        let s = scenario(name, backend, timed);
        let name = match backend {
            Backend::Mujoco => format!("{name}_mujoco"),
            Backend::Rapier => format!("{name}_rapier_32links_5ms"),
        };
        let models = ModelCache::default();
        // Only for the benches a filter (`cargo bench --bench scenario -- mujoco`) selects: the
        // rapier ones take minutes.
        if timed && selected(&name) {
            print_real_time_factor(&name, &s, &models);
        }
        group.bench_function(&name, |b| b.iter(|| run_on_twin(&s, &models, None).expect("runs")));
    }
    group.finish();
}

/// Whether criterion's filter (the first argument that is not a flag) selects the bench `name`;
/// no filter selects every one.
fn selected(name: &str) -> bool {
    std::env::args().skip(1).find(|a| !a.starts_with('-')).is_none_or(|filter| name.contains(&filter))
}

/// Runs `s` twice (the second with the model already compiled), checks both agree and prints the
/// simulated seconds per wall second.
fn print_real_time_factor(name: &str, s: &PickPlaceScenario, models: &ModelCache) {
    let (summary, _) = run_on_twin(s, models, None).expect("runs");
    let started = Instant::now();
    let (again, _) = run_on_twin(s, models, None).expect("runs");
    let wall = started.elapsed().as_secs_f64();
    assert_eq!(summary.outcome, again.outcome, "deterministic");
    println!(
        "{name}: {:.1} simulated s in {:.3} s wall = {:.0}x real time (one core, model compiled once)",
        again.sim_time_s,
        wall,
        again.sim_time_s / wall
    );
}

criterion_group!(benches, full_scenario);
criterion_main!(benches);
