//! The physics layer against analytic cases, all with the project's default `[physics]` settings.

use mujoco_rs::mujoco_c::_mjtObjBase::{mjOBJ_ACTUATOR, mjOBJ_BODY, mjOBJ_GEOM};
use mujoco_rs::prelude::{MjData, MjModel};
use tendril::cell::physics::{
    Integrator, ObjectConfig, ObjectName, PhysicsConfig, PhysicsError, Scene, SceneModel, SceneSpec, validation,
};

const G: f64 = 9.81;

fn body(m: &MjModel, name: &str) -> usize {
    m.name_to_id(mjOBJ_BODY, name).unwrap()
}

/// Sum of contact normal forces on geom `g` [N].
fn normal_force_on(d: &MjData<&MjModel>, g: usize) -> f64 {
    d.contact()
        .iter()
        .enumerate()
        .filter(|(_, c)| c.geom1 as usize == g || c.geom2 as usize == g)
        .map(|(i, _)| d.contact_force(i)[0])
        .sum()
}

#[test]
fn resting_box_normal_force_equals_weight() {
    let p = PhysicsConfig::default();
    let m = validation::box_on_plane(&p).unwrap();
    let mut d = m.make_data();
    for _ in 0..(1.0 / p.timestep_s) as usize {
        d.step();
    }
    let g = m.name_to_id(mjOBJ_GEOM, "box").unwrap();
    let n = normal_force_on(&d, g);
    let weight = 1.0 * -m.opt().gravity[2];
    assert!(((n - weight) / weight).abs() < 1e-3, "normal force {n} N vs m g {weight} N");
}

/// Displacement of the box along the slope after `seconds` [m].
fn slope_slide(angle_deg: f64, seconds: f64) -> f64 {
    let p = PhysicsConfig::default();
    let m = validation::slope(&p, angle_deg.to_radians()).unwrap();
    let mut d = m.make_data();
    d.forward();
    let b = body(&m, "box");
    let start = d.xpos()[b];
    for _ in 0..(seconds / p.timestep_s) as usize {
        d.step();
    }
    let end = d.xpos()[b];
    (0..3).map(|k| (end[k] - start[k]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn slope_holds_below_and_slides_above_the_friction_angle() {
    let critical = 0.5f64.atan().to_degrees();
    let held = slope_slide(critical - 0.5, 2.0);
    assert!(held < 0.5e-3, "box crept {held} m at {:.3} deg", critical - 0.5);
    let slid = slope_slide(critical + 0.5, 2.0);
    // Analytic: a = g (sin - mu cos) = 0.096 m/s^2 -> 0.19 m in 2 s; demand at least half of it.
    let a = G * ((critical + 0.5).to_radians().sin() - 0.5 * (critical + 0.5).to_radians().cos());
    assert!(slid > 0.5 * 0.5 * a * 4.0, "box slid only {slid} m at {:.3} deg", critical + 0.5);
}

/// Whether two pads pressing `force` N each hold the box while the carriage accelerates up at `a`.
fn pinch_holds(force: f64, mu: f64, a: f64) -> bool {
    let p = PhysicsConfig::default();
    let m = validation::pinch(&p, mu).unwrap();
    let mut d = m.make_data();
    let lift = m.name_to_id(mjOBJ_ACTUATOR, "lift").unwrap();
    // Carriage, pads and box [kg] (models/validation/pinch.xml).
    let (total, boxm) = (100.0 + 0.1 + 0.35, 0.35);
    for name in ["squeeze_l", "squeeze_r"] {
        d.ctrl_mut()[m.name_to_id(mjOBJ_ACTUATOR, name).unwrap()] = force;
    }
    d.forward();
    let (b, c) = (body(&m, "box"), body(&m, "carriage"));
    let (settle, accelerate) = (0.2, 0.5);
    let settle_steps = (settle / p.timestep_s) as usize;
    d.ctrl_mut()[lift] = boxm * G;
    for _ in 0..settle_steps {
        d.step();
    }
    // Slip is counted from the start of the acceleration (the settling grip may sink a little).
    let rel0 = d.xpos()[b][2] - d.xpos()[c][2];
    d.ctrl_mut()[lift] = boxm * G + total * a;
    for _ in 0..(accelerate / p.timestep_s) as usize {
        d.step();
    }
    let slip = rel0 - (d.xpos()[b][2] - d.xpos()[c][2]);
    slip < 1e-3
}

#[test]
fn pinch_holding_force_matches_analytic_bound() {
    let (mass, mu, a) = (0.35, 0.8, 2.0);
    let analytic = mass * (G + a) / (2.0 * mu);
    let (mut lo, mut hi) = (0.5 * analytic, 2.0 * analytic);
    assert!(!pinch_holds(lo, mu, a) && pinch_holds(hi, mu, a), "bracket fails");
    for _ in 0..10 {
        let mid = 0.5 * (lo + hi);
        if pinch_holds(mid, mu, a) { hi = mid } else { lo = mid }
    }
    let found = 0.5 * (lo + hi);
    let err = (found - analytic) / analytic;
    eprintln!("pinch: smallest holding force {found:.4} N, analytic {analytic:.4} N ({:+.3} %)", err * 100.0);
    assert!(err.abs() < 0.05, "smallest holding force {found:.4} N vs analytic {analytic:.4} N ({:.2} %)", err * 100.0);
}

/// Tendon winding speed of the test grasps [m/s]: a slow, steady wrap (a quarter of the motor's top
/// speed; winding at full speed flings the strip's tip around the handle and can push the object).
const WIND_M_S: f64 = 0.0075;

/// Builds the scene, grows the finger (3.5 s at the motor's speed), winds `twine` m of tendon at
/// [`WIND_M_S`], then holds `hold` s.
fn grasp(spec: &SceneSpec, twine: f64, hold: f64) -> Result<Scene, PhysicsError> {
    let mut s = Scene::build(spec)?;
    s.set_growth(spec.finger.length_m)?;
    s.run_for(3.5)?;
    let steps = (twine / WIND_M_S / s.timestep()).round().max(1.0) as usize;
    for k in 1..=steps {
        s.set_twine(twine * k as f64 / steps as f64)?;
        s.step()?;
    }
    s.run_for(hold)?;
    Ok(s)
}

#[test]
fn pad_force_equals_mujoco_contact_force_on_the_pad() {
    let s = grasp(&SceneSpec::default(), 0.03, 0.2).unwrap();
    let r = s.readout();
    assert!(r.pad_force_n > 0.1, "pad not loaded: {r:?}");
    let touch = s.pad_touch_sensor_n();
    assert!((r.pad_force_n - touch).abs() < 1e-9 * touch.max(1.0), "readout {} vs touch sensor {touch}", r.pad_force_n);
    assert!(r.grip_force_n >= r.pad_force_n && r.touching);
}

#[test]
fn more_twine_gives_more_grip_and_pad_force() {
    // Grown (3.5 s at the motor's speed), then the tendon wound steadily from 0 to 45 mm: from 27 mm on
    // (the wrap has formed) the pad force and the hand's total normal force on the object (strip and
    // palm) rise at every 0.3 s sample, for every object.
    for name in [ObjectName::Crimper, ObjectName::Hammer, ObjectName::Shampoo] {
        let spec = SceneSpec { object: Some(ObjectConfig { name, ..ObjectConfig::default() }), ..SceneSpec::default() };
        let mut s = Scene::build(&spec).unwrap();
        s.set_growth(spec.finger.length_m).unwrap();
        s.run_for(3.5).unwrap();
        let n = (0.045 / WIND_M_S / s.timestep()).round() as usize;
        let every = (0.3 / s.timestep()).round() as usize;
        let mut last: Option<tendril::cell::physics::PhysicsReadout> = None;
        let mut curve = String::new();
        for k in 1..=n {
            s.set_twine(0.045 * k as f64 / n as f64).unwrap();
            s.step().unwrap();
            let r = s.readout();
            if k % every != 0 || r.twine_setpoint_m < 0.027 {
                continue;
            }
            curve += &format!(
                " {:.1}mm:{:.2}/{:.2}",
                r.twine_setpoint_m * 1e3,
                r.pad_force_n,
                r.grip_force_n + r.palm_force_n
            );
            if let Some(l) = &last {
                assert!(
                    r.pad_force_n > l.pad_force_n && r.grip_force_n + r.palm_force_n > l.grip_force_n + l.palm_force_n,
                    "{name:?} at twine {:.4}: pad {:.3} -> {:.3} N, total {:.3} -> {:.3} N",
                    r.twine_setpoint_m,
                    l.pad_force_n,
                    r.pad_force_n,
                    l.grip_force_n + l.palm_force_n,
                    r.grip_force_n + r.palm_force_n
                );
            }
            last = Some(r);
        }
        eprintln!("{name:?} twine:pad/total N{curve}");
    }
}

#[test]
fn contact_force_relaxes_under_a_fixed_twine() {
    let mut s = grasp(&SceneSpec::default(), 0.03, 0.5).unwrap();
    let early = s.readout();
    s.run_for(4.0).unwrap();
    let late = s.readout();
    assert!(
        late.grip_force_n < 0.95 * early.grip_force_n,
        "no creep: {} -> {} N",
        early.grip_force_n,
        late.grip_force_n
    );
    assert!(late.creep_m > early.creep_m);
}

#[test]
fn a_loose_grip_lets_the_object_slip_out() {
    // Lift the hand 10 cm in 1 s with a twine that barely touches: the object stays behind.
    let mut s = grasp(&SceneSpec::default(), 0.015, 0.2).unwrap();
    let z0 = s.readout().object_in_hand_m[2];
    let start = tendril::cell::physics::ur5e::forward(&tendril::cell::physics::ur5e::HOME);
    let mut seed = tendril::cell::physics::ur5e::HOME;
    for k in 1..=(1.0 / s.timestep()) as usize {
        let mut target = start;
        target.translation.vector.z += 0.1 * (k as f64 * s.timestep()).min(1.0);
        seed = tendril::cell::physics::ur5e::inverse_near(&target, &seed).unwrap();
        s.set_arm_target(seed).unwrap();
        s.step().unwrap();
    }
    s.run_for(0.5).unwrap();
    let slip = s.readout().object_in_hand_m[2] - z0;
    assert!(slip > 0.02, "object slipped only {slip} m");
}

#[test]
fn objects_have_the_papers_masses() {
    for name in [ObjectName::Crimper, ObjectName::Hammer, ObjectName::Shampoo] {
        let spec = SceneSpec { object: Some(ObjectConfig { name, ..ObjectConfig::default() }), ..SceneSpec::default() };
        let sm = SceneModel::build(&spec).unwrap();
        let m = sm.model();
        let mass = m.body_mass()[body(m, "object")];
        assert!((mass - name.paper_mass_kg()).abs() < 1e-9, "{name:?}: {mass} kg");
        // The grip geometry Rust places by matches the model file, and the strip's whole helix (width,
        // plus its rise over the full length) lies on the grip capsule's straight part.
        let g = m.name_to_id(mjOBJ_GEOM, "object_grip").unwrap();
        assert!((m.geom_size()[g][0] - name.grip_radius_m()).abs() < 1e-12, "{name:?} grip radius");
        let (centre, half) = (m.geom_pos()[g][2], m.geom_size()[g][1]);
        let f = &spec.finger;
        let (low, high) = (
            name.grip_height_m() - f.width_m / 2.0,
            name.grip_height_m() + f.width_m / 2.0 + f.helix_slope * f.length_m,
        );
        assert!(
            low >= centre - half && high <= centre + half + name.grip_radius_m(),
            "{name:?} helix {low}..{high} m off the grip"
        );
    }
}

#[test]
fn same_inputs_give_bit_identical_trajectories() {
    let a = grasp(&SceneSpec::default(), 0.03, 0.3).unwrap();
    let b = grasp(&SceneSpec::default(), 0.03, 0.3).unwrap();
    assert_eq!(a.data().qpos(), b.data().qpos());
    assert_eq!(a.data().qvel(), b.data().qvel());
}

#[test]
fn runs_sharing_one_model_across_threads_match_a_sequential_run() {
    let shared = SceneModel::build(&SceneSpec::default()).unwrap();
    let run = |shared: std::sync::Arc<SceneModel>| {
        let mut s = Scene::new(shared);
        s.set_growth(0.14).unwrap();
        s.run_for(3.5).unwrap();
        s.set_twine(0.01).unwrap();
        s.run_for(1.0).unwrap();
        s.data().qpos().to_vec()
    };
    let sequential = run(shared.clone());
    let threads: Vec<_> = (0..2)
        .map(|_| {
            std::thread::spawn({
                let shared = shared.clone();
                move || run(shared)
            })
        })
        .collect();
    for t in threads {
        assert_eq!(t.join().unwrap(), sequential);
    }
}

#[test]
fn an_unstable_setting_is_reported_with_its_time() {
    // Euler at 20 ms with an undamped, very stiff motor servo: omega * dt = sqrt(kp / m) * dt = 45,
    // far beyond the explicit stability limit of 2. The strip is flung through the guide.
    let mut spec = SceneSpec::default();
    spec.physics.integrator = Integrator::Euler;
    spec.physics.timestep_s = 0.02;
    spec.finger.motor_kp_n_m = 1e7;
    spec.finger.motor_kv_n_s_m = 0.0;
    match grasp(&spec, 0.03, 5.0) {
        Err(PhysicsError::Diverged { time_s, cause }) => {
            eprintln!("unstable setting reported: t = {time_s} s, {cause}");
            assert!(time_s > 0.0 && time_s < 1.0, "time {time_s}");
            assert!(!format!("{cause}").is_empty());
        }
        Err(e) => panic!("expected a divergence, got {e}"),
        Ok(s) => panic!("expected a divergence, ran to t = {} with {:?}", s.time(), s.readout()),
    }
}

#[test]
fn bad_inputs_are_errors_not_nan() {
    let mut s = Scene::build(&SceneSpec::default()).unwrap();
    assert!(matches!(s.set_twine(f64::NAN), Err(PhysicsError::BadInput { .. })));
    assert!(matches!(s.set_arm_target([0.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0]), Err(PhysicsError::BadInput { .. })));
    let mut spec = SceneSpec::default();
    spec.finger.segments = 1;
    assert!(matches!(SceneModel::build(&spec), Err(PhysicsError::Config { key, .. }) if key == "finger.segments"));
}

#[test]
fn arm_models_put_the_hand_where_dh_kinematics_says() {
    use tendril::cell::physics::{ArmMode, ur5e};
    let q = [-1.3, -1.9, 1.7, -1.4, -1.5, 0.4];
    for mode in [ArmMode::Kinematic, ArmMode::Dynamic] {
        let mut spec = SceneSpec { object: None, arm_q0: q, ..SceneSpec::default() };
        spec.physics.arm_mode = mode;
        let s = Scene::build(&spec).unwrap();
        // At the start both modes are exactly at the pose (MJCF body chain vs DH product).
        let fk = ur5e::forward(&q).translation.vector;
        let hand = s.readout().hand_pos_m;
        let err = ((hand[0] - fk.x).powi(2) + (hand[1] - fk.y).powi(2) + (hand[2] - fk.z).powi(2)).sqrt();
        assert!(err < 1e-9, "{mode:?}: hand {hand:?} vs DH {fk}");
    }
    // Moving: the hand follows a new target within 2 mm once settled, in both modes.
    let target = [-1.5, -1.7, 1.8, -1.7, -1.57, 0.0];
    for mode in [ArmMode::Kinematic, ArmMode::Dynamic] {
        let mut spec = SceneSpec { object: None, arm_q0: q, ..SceneSpec::default() };
        spec.physics.arm_mode = mode;
        let mut s = Scene::build(&spec).unwrap();
        s.set_arm_target(target).unwrap();
        s.run_for(2.0).unwrap();
        let fk = ur5e::forward(&target).translation.vector;
        let hand = s.readout().hand_pos_m;
        let err = ((hand[0] - fk.x).powi(2) + (hand[1] - fk.y).powi(2) + (hand[2] - fk.z).powi(2)).sqrt();
        assert!(err < 2e-3, "{mode:?}: hand {hand:?} vs DH {fk} ({err} m)");
    }
}
