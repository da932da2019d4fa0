//! The guide's walls left out of the collision search once the strip has grown (issue 39, lever
//! 3; `crates/twin/src/physics/guide.rs`) change nothing: a run that steps the pruned model gives
//! the trace, byte for byte, of the same run with the walls kept in throughout. The six Section V
//! runs are also held to their fixture by tests/section_v_unchanged.rs; this test compares the
//! two models directly, on runs with and without feedback.

use std::path::Path;
use tendril_run::clock::RunClock;
use tendril_run::execute::run_on_cell;
use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::physics::SceneModel;

/// `object`'s shipped scenario, seed 1, with or without feedback.
fn scenario(object: &str, feedback: bool) -> PickPlaceScenario {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios").join(format!("{object}.toml"));
    let overrides = [format!("feedback={feedback}"), "seed=1".into()].map(|s| s.parse().expect("valid"));
    tendril_config::load(&file, &overrides).expect("shipped scenarios load")
}

/// Runs `s` on `model`, returning its trace.csv and whether the run ended on the pruned model.
fn trace(s: &PickPlaceScenario, model: std::sync::Arc<SceneModel>, out: &Path) -> (Vec<u8>, bool) {
    let mut cell = s.sim_cell(model);
    run_on_cell(&mut cell, s, Some(out), RunClock::start()).expect("runs");
    let data = cell.mujoco_data_mut().expect("MuJoCo");
    let wall = data.model().name_to_id(mujoco_rs::mujoco_c::_mjtObjBase::mjOBJ_GEOM, "guide_wall_in").expect("wall");
    let pruned = data.model().geom_conaffinity()[wall] == 0;
    (std::fs::read(out.join("trace.csv")).expect("trace"), pruned)
}

#[test]
fn the_pruned_model_gives_the_unpruned_trace() {
    let dir = tempfile::tempdir().unwrap();
    // A held object, and two drops: a falling object swings the strip about, near the guide too.
    for (object, feedback) in [("crimper", true), ("crimper", false), ("hammer", false)] {
        let s = scenario(object, feedback);
        let model = SceneModel::build(&s.scene_spec()).expect("builds");
        assert!(model.prunes_guide(), "the default finger's guide can be pruned");
        let name = format!("{object}-{feedback}");
        let (pruned, ended_pruned) = trace(&s, model.clone(), &dir.path().join(format!("{name}-pruned")));
        let (kept, ended_kept) = trace(&s, model.without_guide_pruning(), &dir.path().join(format!("{name}-kept")));
        if feedback {
            assert!(ended_pruned, "{name}: the grown strip's run ends on the pruned model");
        }
        assert!(!ended_kept, "{name}: the reference keeps the walls");
        assert!(pruned == kept, "{name}: the pruned model's trace differs from the unpruned one");
    }
}
