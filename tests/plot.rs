//! Charts from synthetic files: every chart is written as PNG (decoding to its size) and SVG
//! (holding its title), and bad input is an error naming the file and the line.
//!
//! Set `TENDRIL_PLOT_DEMO=DIR` to keep the synthetic inputs and charts in DIR for a look.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tendril_plot as plot;

fn workdir(name: &str) -> (Option<tempfile::TempDir>, PathBuf) {
    match std::env::var("TENDRIL_PLOT_DEMO") {
        Ok(d) => {
            let p = Path::new(&d).join(name);
            std::fs::create_dir_all(&p).unwrap();
            (None, p)
        }
        Err(_) => {
            let t = tempfile::tempdir().unwrap();
            let p = t.path().to_path_buf();
            (Some(t), p)
        }
    }
}

const TRACE_HEADER: &str = "time_s,phase,true_force_n,fbg1_nm,fbg2_nm,force_n,force_uncompensated_n,over_range,setpoint_n,\
controller_on,controller_output_deg_s,growth_motor_rad,twine_motor_rad,object_height_m,slip_speed_m_s,grip_force_n";

/// A 17 s run at `hz`: contact in wrap, PI rise in grasp, the arm moves from 8 s; dropped at
/// 11 s when `drop` is set.
fn write_run(dir: &Path, drop: bool, hz: usize) {
    let phases = [
        (1.0, "home"),
        (3.0, "grow"),
        (5.0, "wrap"),
        (8.0, "grasp"),
        (9.5, "lift"),
        (13.0, "transfer"),
        (14.5, "lower"),
        (16.0, "release"),
        (17.0, "done"),
    ];
    let mut s = format!("{TRACE_HEADER}\n");
    let mut f = 0.0f64;
    let dt = 1.0 / hz as f64;
    for i in 0..17 * hz {
        let t = i as f64 * dt;
        let phase = phases.iter().find(|p| t < p.0).map_or("done", |p| p.1);
        let control = (5.0..14.5).contains(&t) && !(drop && t >= 11.0);
        let target = match phase {
            "wrap" => 0.3 * (t - 3.0) / 2.0,
            "grasp" | "lift" | "transfer" | "lower" => 1.0 + 0.15 * (6.0 * t).sin() * f64::from(u8::from(t > 8.0)),
            _ => 0.0,
        };
        let target = if drop && t >= 11.0 { 0.0 } else { target };
        f += (target - f) * (8.0 * dt).min(1.0);
        let out = if control { 40.0 * (1.0 - f) + 5.0 * (3.0 * t).cos() } else { 0.0 };
        let truth = if t < 0.2 { f64::NAN } else { f * 1.03 };
        writeln!(
            s,
            "{t:.4},{phase},{truth:.5},1550.1,1550.2,{f:.5},{:.5},0,1.000,{},{out:.3},0,0,0,0,0",
            f + 0.02 * t,
            u8::from(control)
        )
        .unwrap();
    }
    std::fs::write(dir.join("trace.csv"), s).unwrap();
    let (outcome, drop_fields) = if drop {
        ("dropped", r#""drop_time_s": 3.0, "drop_cell_time_s": 11.0, "drop_phase": "transfer", "slip_detected_s": 2.4"#)
    } else {
        ("held", r#""drop_time_s": null, "drop_cell_time_s": null, "drop_phase": null"#)
    };
    let summary = format!(
        r#"{{"scenario": "grip-cup", "object": "cup", "mass_kg": 0.1, "feedback": true,
  "gains": {{"kp": 2.0, "ki": 0.5, "kd": 0.0}}, "setpoint_n": 1.0, "outcome": "{outcome}", {drop_fields},
  "rise_time_90_s": 0.8, "overshoot_pct": 4.0, "seed": 1, "backend": "mujoco", "error": null}}"#
    );
    std::fs::write(dir.join("summary.json"), summary).unwrap();
}

fn write_sweep(dir: &Path) {
    let mut s = String::from(
        "run_id,scenario_file,controller.kp,controller.ki,scenario,object,mass_kg,feedback,gains.kp,gains.ki,gains.kd,\
setpoint_n,outcome,drop_time_s,drop_cell_time_s,drop_phase,slip_detected_s,rise_time_90_s,overshoot_pct,\
max_fluctuation_pct,min_moving_force_n,force_rmse_n,sim_time_s,wall_time_s,real_time_factor,seed,backend,error\n",
    );
    let mut id = 0;
    for (object, mass) in [("cup", 0.05), ("bottle", 0.3), ("box", 0.15)] {
        for kp in [0.5, 1.0, 2.0, 4.0, 8.0, 16.0] {
            for ki in [0.0, 0.25, 0.5, 1.0, 2.0] {
                let held = kp * (1.0 + ki) > mass * 20.0 && kp < 12.0;
                let error = kp == 16.0 && ki == 2.0;
                let outcome = if error {
                    "error"
                } else if held {
                    "held"
                } else {
                    "dropped"
                };
                let rise = if error { String::new() } else { format!("{:.3}", 2.0 / (kp * (1.0 + ki))) };
                let over = if error { String::new() } else { format!("{:.2}", kp * ki * 1.5) };
                let fl = if held { format!("{:.2}", 30.0 / kp + 3.0 * ki) } else { String::new() };
                let err = if error { "\"solver diverged at t=3.1 s, in wrap\"" } else { "" };
                writeln!(
                    s,
                    "{id},scenarios/grip.toml,{kp},{ki},grip,{object},{mass},true,{kp},{ki},0,1,{outcome},,,,,{rise},{over},{fl},,,20,2,10,1,mujoco,{err}"
                )
                .unwrap();
                id += 1;
            }
        }
    }
    std::fs::write(dir.join("results.csv"), s).unwrap();
}

fn write_speed_accuracy(dir: &Path) {
    let mut s = String::from(
        "backend,integrator,cone,timestep_s,segments,sim_s_per_cpu_s,force_rmse_n,drop_time_error_s,status,is_default,is_reference\n",
    );
    for (k, integrator) in ["Euler", "implicitfast", "implicit", "RK4"].iter().enumerate() {
        for dt in [0.0005, 0.001, 0.002, 0.005] {
            for cone in ["pyramidal", "elliptic"] {
                for segs in [8, 16] {
                    let cost =
                        [1.0, 1.3, 1.8, 4.0][k] * f64::from(segs) / 8.0 * if cone == "elliptic" { 1.4 } else { 1.0 };
                    let speed = dt / 0.0005 * 2.0 / cost;
                    let reference = *integrator == "RK4" && dt == 0.0005 && cone == "elliptic" && segs == 16;
                    let default = *integrator == "implicitfast" && dt == 0.002 && cone == "pyramidal" && segs == 8;
                    let diverged = *integrator == "Euler" && dt == 0.005;
                    let drop_err = if diverged {
                        String::new()
                    } else if reference {
                        "0".into()
                    } else {
                        format!("{:.4}", dt * [2.0, 1.0, 1.0, 0.5][k] * if segs == 8 { 3.0 } else { 1.0 })
                    };
                    let rmse = if reference {
                        0.0
                    } else {
                        0.004 + [3.0, 1.0, 0.8, 0.2][k] * dt * 20.0 + if segs == 8 { 0.01 } else { 0.0 }
                    };
                    let (rmse, status) =
                        if diverged { (String::new(), "diverged") } else { (format!("{rmse:.5}"), "ok") };
                    writeln!(
                        s,
                        "mujoco,{integrator},{cone},{dt},{segs},{speed:.3},{rmse},{drop_err},{status},{default},{reference}"
                    )
                    .unwrap();
                }
            }
        }
    }
    std::fs::write(dir.join("speed_accuracy.csv"), s).unwrap();
}

/// A produce item's study: the flex's columns, colour by its degrees of freedom.
#[test]
fn a_produce_item_s_speed_accuracy_rows_carry_their_flex_and_draw_by_it() {
    let (_keep, dir) = workdir("speed_produce");
    let head = "backend,integrator,cone,solver,timestep_s,segments,base_refinement,fine_from_m,sim_s_per_cpu_s,\
                force_rmse_n,drop_time_error_s,status,is_default,is_reference,produce_grid,produce_dof,peak_pressure_error_pct";
    let rows = [
        "mujoco,discrete,elliptic,newton,0.000625,16,8,0,0.3,0,0,ok,false,true,13,quadratic,0",
        "mujoco,discrete,elliptic,newton,0.0025,8,8,0,4.0,0.2,,ok,true,false,7,trilinear,20.5",
        "mujoco,discrete,elliptic,newton,0.0025,8,8,0,2.0,0.05,0.1,ok,false,false,7,quadratic,3.1",
        "mujoco,discrete,elliptic,cg,0.0025,8,8,0,4.5,0.21,,ok,false,false,7,trilinear,",
    ];
    std::fs::write(dir.join("speed_accuracy.csv"), format!("{head}\n{}\n", rows.join("\n"))).unwrap();
    let rows = plot::speed_accuracy::read(&dir.join("speed_accuracy.csv")).unwrap();
    assert_eq!(rows[1].produce_grid, Some(7));
    assert_eq!(rows[2].produce_dof.as_deref(), Some("quadratic"));
    assert_eq!((rows[1].peak_pressure_error_pct, rows[3].peak_pressure_error_pct), (Some(20.5), None));
    plot::speed_accuracy::render(&rows, &dir).unwrap();
    let svg = std::fs::read_to_string(dir.join("speed_accuracy.svg")).unwrap();
    assert!(svg.contains("trilinear flex + CG") && svg.contains("quadratic flex") && svg.contains("7 pts"), "{svg}");
}

fn write_stability(dir: &Path, backends: &[&str]) {
    let mut s = String::from("backend,integrator,timestep_s,outcome\n");
    let limits = [("Euler", 1e-3), ("implicitfast", 5e-3), ("implicit", 1e-2), ("RK4", 2e-3)];
    for (b, (integrator, limit)) in backends.iter().flat_map(|b| limits.iter().map(move |l| (b, *l))) {
        let limit = if *b == "mujoco" { limit } else { limit / 2.0 };
        for dt in [1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2] {
            let outcome = if dt <= limit {
                "stable"
            } else if dt <= limit * 2.5 {
                if integrator == "implicit" { "lost_grasp" } else { "penetration" }
            } else {
                "diverged"
            };
            writeln!(s, "{b},{integrator},{dt},{outcome}").unwrap();
        }
    }
    std::fs::write(dir.join("stability.csv"), s).unwrap();
}

fn write_gain_map(dir: &Path) {
    let mut s = String::from("object,kp,ki,outcome,oscillating\n");
    for (object, need) in [("cup", 1.0), ("bottle", 4.0), ("box", 2.0)] {
        for kp in [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0] {
            for ki in [0.0, 0.5, 1.0, 2.0, 4.0, 8.0] {
                let osc = kp * (1.0 + ki) > 40.0;
                let held = kp * (1.0 + ki) >= need && kp * (1.0 + ki) < 120.0;
                writeln!(s, "{object},{kp},{ki},{},{osc}", if held { "held" } else { "dropped" }).unwrap();
            }
        }
    }
    std::fs::write(dir.join("gain_map.csv"), s).unwrap();
}

/// Asserts the chart pair exists: the PNG decodes to `size`, the SVG holds `title`.
fn check_pair(files: &[PathBuf], stem: &str, size: (u32, u32), title: &str) {
    let png = files.iter().find(|f| f.file_name().unwrap() == format!("{stem}.png").as_str());
    let png = png.unwrap_or_else(|| panic!("no {stem}.png in {files:?}"));
    let decoder = png::Decoder::new(std::fs::File::open(png).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), size, "{}", png.display());
    // Not a blank canvas: a good share of pixels is not white.
    let inked = buf.chunks(3).filter(|p| p.iter().any(|c| *c < 200)).count();
    assert!(inked > buf.len() / 3 / 50, "{} looks blank", png.display());
    // The title band is inked: text renders from the embedded font, no system font needed.
    let title_band = &buf[..(size.0 * 3 * 34) as usize];
    let dark = title_band.chunks(3).filter(|p| p.iter().all(|c| *c < 100)).count();
    assert!(dark > 200, "{}: title text missing ({dark} dark pixels)", png.display());
    let svg = png.with_extension("svg");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains(title), "{} lacks its title {title:?}", svg.display());
}

#[test]
fn run_trace_held_and_dropped() {
    for (name, drop) in [("run-held", false), ("run-dropped", true)] {
        let (_keep, dir) = workdir(name);
        write_run(&dir, drop, 100);
        let run = plot::trace::read(&dir).unwrap();
        assert!(run.points[0].true_force_n.is_nan());
        let files = plot::trace::render(&run, &dir).unwrap();
        check_pair(&files, "trace", (1400, 900), "Force trace: grip-cup");
        let svg = std::fs::read_to_string(dir.join("trace.svg")).unwrap();
        assert_eq!(svg.contains("drop at 11 s (transfer)"), drop);
        assert_eq!(svg.contains("slip detected"), drop);
        assert!(svg.contains("arm starts moving"));
        assert!(svg.contains("transfer") && svg.contains("grasp"), "phases named");
    }
}

#[test]
fn sweep_heatmaps_per_object() {
    let (_keep, dir) = workdir("sweep");
    write_sweep(&dir);
    let rows = plot::sweep::read(&dir.join("results.csv")).unwrap();
    assert_eq!(rows.len(), 90);
    let files = plot::sweep::render(&rows, &dir).unwrap();
    assert_eq!(files.len(), 6);
    for object in ["cup", "bottle", "box"] {
        check_pair(&files, &format!("sweep_{object}"), (1600, 1200), &format!("Gain sweep: {object}"));
    }
    let svg = std::fs::read_to_string(dir.join("sweep_box.svg")).unwrap();
    assert!(svg.contains("Rise time") && svg.contains("Overshoot") && svg.contains("fluctuation"));
}

#[test]
fn speed_accuracy_chart_and_front() {
    let (_keep, dir) = workdir("speed");
    write_speed_accuracy(&dir);
    let rows = plot::speed_accuracy::read(&dir.join("speed_accuracy.csv")).unwrap();
    let front = plot::speed_accuracy::pareto_front(&rows);
    assert!(front.len() >= 2);
    // No point on the front is beaten on both counts by any plotted point.
    for i in &front {
        let (s, e) = (rows[*i].sim_s_per_cpu_s.unwrap(), rows[*i].force_rmse_n.unwrap());
        assert!(
            rows.iter()
                .filter(|r| r.status == "ok" && r.force_rmse_n.unwrap_or(0.0) > 0.0)
                .all(|r| { !(r.sim_s_per_cpu_s.unwrap() > s && r.force_rmse_n.unwrap() < e) })
        );
    }
    // Diverged and reference (zero error) rows are never on the front.
    assert!(front.iter().all(|i| rows[*i].status == "ok" && !rows[*i].is_reference));
    let files = plot::speed_accuracy::render(&rows, &dir).unwrap();
    check_pair(&files, "speed_accuracy", (1200, 1160), "Speed against accuracy");
    assert!(std::fs::read_to_string(dir.join("speed_accuracy.svg")).unwrap().contains("Drop-time error"));
    let svg = std::fs::read_to_string(dir.join("speed_accuracy.svg")).unwrap();
    assert!(svg.contains("default: 2 ms") && svg.contains("reference: 500 µs"));
}

/// The study's newer columns: a CG point gets its own series, a graded finger its grading in labels.
#[test]
fn speed_accuracy_chart_names_solver_and_graded_finger() {
    let (_keep, dir) = workdir("speed-graded");
    let csv = "backend,integrator,cone,solver,timestep_s,segments,base_refinement,sim_s_per_cpu_s,force_rmse_n,drop_time_error_s,status,is_default,is_reference
mujoco,implicitfast,elliptic,newton,0.0003125,256,1,0.1,0,0,ok,false,true
mujoco,implicitfast,elliptic,newton,0.00125,64,1,8,0.01,0.3,ok,true,false
mujoco,implicitfast,elliptic,cg,0.00125,64,1,12,0.012,0.3,ok,false,false
mujoco,implicitfast,elliptic,newton,0.00125,8,8,20,0.009,0.2,ok,false,false
";
    std::fs::write(dir.join("speed_accuracy.csv"), csv).unwrap();
    let rows = plot::speed_accuracy::read(&dir.join("speed_accuracy.csv")).unwrap();
    assert_eq!((rows[2].solver.as_str(), rows[3].base_refinement), ("cg", 8));
    assert_eq!((rows[1].solver.as_str(), rows[1].base_refinement), ("newton", 1));
    // The graded finger is faster and more accurate than both 64-link points: the front's only one.
    assert_eq!(plot::speed_accuracy::pareto_front(&rows), vec![3]);
    plot::speed_accuracy::render(&rows, &dir).unwrap();
    let svg = std::fs::read_to_string(dir.join("speed_accuracy.svg")).unwrap();
    assert!(svg.contains("implicitfast + CG"), "the CG series is in the legend");
    assert!(svg.contains("8 links (base x8)"), "the front's graded point is labelled with its grading");
}

/// A finger whose fine links start above the base (`fine_from_m`) is read and labelled with where
/// they start; a file without the column reads as fine from the base.
#[test]
fn speed_accuracy_chart_labels_a_fine_zone() {
    let (_keep, dir) = workdir("speed-zone");
    let csv = "backend,integrator,cone,solver,timestep_s,segments,base_refinement,fine_from_m,sim_s_per_cpu_s,force_rmse_n,drop_time_error_s,status,is_default,is_reference
mujoco,implicitfast,elliptic,newton,0.0003125,256,1,0,0.1,0,0,ok,false,true
mujoco,implicitfast,elliptic,newton,0.0025,8,8,0,40,0.014,0.4,ok,true,false
mujoco,implicitfast,elliptic,newton,0.0025,8,8,0.0175,50,0.012,3.3,ok,false,false
";
    std::fs::write(dir.join("speed_accuracy.csv"), csv).unwrap();
    let rows = plot::speed_accuracy::read(&dir.join("speed_accuracy.csv")).unwrap();
    assert_eq!((rows[1].fine_from_m, rows[2].fine_from_m), (0.0, 0.0175));
    assert_eq!(plot::speed_accuracy::pareto_front(&rows), vec![2]);
    plot::speed_accuracy::render(&rows, &dir).unwrap();
    let svg = std::fs::read_to_string(dir.join("speed_accuracy.svg")).unwrap();
    assert!(svg.contains("8 links (base x8 from 17.5 mm)"), "the front's zoned point names its zone");
    let without = csv
        .replace(",fine_from_m", "")
        .replace(",8,8,0,", ",8,8,")
        .replace(",8,8,0.0175,", ",8,8,")
        .replace(",256,1,0,", ",256,1,");
    std::fs::write(dir.join("speed_accuracy.csv"), without).unwrap();
    let rows = plot::speed_accuracy::read(&dir.join("speed_accuracy.csv")).unwrap();
    assert!(rows.iter().all(|r| r.fine_from_m == 0.0));
}

#[test]
fn stability_chart_marks_largest_stable() {
    let (_keep, dir) = workdir("stability");
    write_stability(&dir, &["mujoco"]);
    let rows = plot::stability::read(&dir.join("stability.csv")).unwrap();
    let euler: Vec<_> = rows.iter().filter(|r| r.integrator == "Euler").collect();
    assert_eq!(plot::stability::largest_stable(&euler), Some(1e-3));
    let files = plot::stability::render(&rows, &dir).unwrap();
    check_pair(&files, "stability", (1100, 260 + 70 * 4), "Stability of the integrators");
}

#[test]
fn gain_maps_per_object() {
    let (_keep, dir) = workdir("gain-map");
    write_gain_map(&dir);
    let rows = plot::gain_map::read(&dir.join("gain_map.csv")).unwrap();
    let files = plot::gain_map::render(&rows, &dir).unwrap();
    assert_eq!(files.len(), 6);
    check_pair(&files, "gain_map_bottle", (1000, 760), "Closed-loop map over the PID gains: bottle");
}

#[test]
fn plot_path_finds_every_input() {
    let (_keep, dir) = workdir("all");
    write_speed_accuracy(&dir);
    write_stability(&dir, &["mujoco"]);
    write_gain_map(&dir);
    let out = dir.join("charts");
    let files = plot::plot_path(&dir, Some(&out)).unwrap();
    assert_eq!(files.len(), 2 + 2 + 6);
    assert!(files.iter().all(|f| f.starts_with(&out) && f.is_file()));
    // A single file draws only its chart.
    let files = plot::plot_path(&dir.join("stability.csv"), Some(&out)).unwrap();
    assert_eq!(files.len(), 2);
}

#[test]
fn bad_input_names_file_and_line() {
    let (_keep, dir) = workdir("bad");
    write_run(&dir, false, 100);
    let trace = dir.join("trace.csv");
    let mut lines: Vec<String> = std::fs::read_to_string(&trace).unwrap().lines().map(String::from).collect();
    lines[4] = lines[4].replacen(",home,", ",home,oops", 1);
    std::fs::write(&trace, lines.join("\n")).unwrap();
    let e = plot::plot_path(&dir, None).unwrap_err().to_string();
    assert!(e.contains("trace.csv:5:") && e.contains("true_force_n"), "{e}");

    lines[4] = "0.1,home".to_string();
    std::fs::write(&trace, lines.join("\n")).unwrap();
    let e = plot::plot_path(&dir, None).unwrap_err().to_string();
    assert!(e.contains("trace.csv:5:") && e.contains("fields"), "{e}");

    std::fs::write(dir.join("stability.csv"), "backend,integrator,outcome\nmujoco,RK4,stable\n").unwrap();
    let e = plot::plot_path(&dir.join("stability.csv"), None).unwrap_err().to_string();
    assert!(e.contains("stability.csv:1:") && e.contains("timestep_s"), "{e}");

    std::fs::write(dir.join("gain_map.csv"), "object,kp,ki,outcome,oscillating\ncup,1,1,wobbly,false\n").unwrap();
    let e = plot::plot_path(&dir.join("gain_map.csv"), None).unwrap_err().to_string();
    assert!(e.contains("gain_map.csv:2:") && e.contains("wobbly"), "{e}");

    std::fs::write(dir.join("summary.json"), "{\n \"outcome\": 3\n}").unwrap();
    write_run(&dir, false, 100);
    std::fs::write(dir.join("summary.json"), "{\n \"outcome\": 3\n}").unwrap();
    let e = plot::trace::read(&dir).unwrap_err().to_string();
    assert!(e.contains("summary.json:2:"), "{e}");

    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let e = plot::plot_path(&empty, None).unwrap_err().to_string();
    assert!(e.contains("no trace.csv"), "{e}");
}

#[test]
fn cli_prints_files_and_fails_cleanly() {
    let (_keep, dir) = workdir("cli");
    write_stability(&dir, &["mujoco"]);
    let bin = env!("CARGO_BIN_EXE_tendril");
    let out = std::process::Command::new(bin).arg("plot").arg(&dir).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(
        stdout.lines().any(|l| l.ends_with("stability.png")) && stdout.lines().any(|l| l.ends_with("stability.svg"))
    );
    let out = std::process::Command::new(bin).arg("plot").arg(dir.join("missing")).output().unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("missing") && !stderr.contains("panicked"), "{stderr}");
}

#[test]
fn dense_gain_grid_still_renders() {
    let (_keep, dir) = workdir("dense");
    let mut s = String::from("object,kp,ki,outcome,oscillating\n");
    for i in 0..30 {
        for j in 0..25 {
            let (kp, ki) = (0.1 * 1.2f64.powi(i), 0.05 * 1.25f64.powi(j));
            writeln!(s, "cup,{kp},{ki},{},{}", if kp * (1.0 + ki) > 1.0 { "held" } else { "dropped" }, kp * ki > 20.0)
                .unwrap();
        }
    }
    std::fs::write(dir.join("gain_map.csv"), s).unwrap();
    let files = plot::plot_path(&dir, None).unwrap();
    check_pair(&files, "gain_map_cup", (1000, 760), "Closed-loop map over the PID gains: cup");
}

#[test]
fn long_trace_is_thinned() {
    let (_keep, dir) = workdir("run-long");
    write_run(&dir, true, 2000);
    let files = plot::plot_path(&dir, None).unwrap();
    check_pair(&files, "trace", (1400, 900), "Force trace");
    // 34,000 ticks x 4 lines would be megabytes of SVG; min/max thinning keeps it small.
    let svg = std::fs::metadata(dir.join("trace.svg")).unwrap().len();
    assert!(svg < 1_500_000, "trace.svg is {svg} bytes");
}

#[test]
fn sweep_cells_pool_repeated_gains() {
    let (_keep, dir) = workdir("sweep-pooled");
    // Only the columns the heatmaps need; two seeds per gain pair with different outcomes.
    let mut s = String::from("object,gains.kp,gains.ki,outcome,rise_time_90_s,overshoot_pct,max_fluctuation_pct\n");
    for kp in [1.0, 2.0] {
        for ki in [0.0, 1.0] {
            writeln!(s, "cup,{kp},{ki},held,6.5,2.0,10.0").unwrap();
            writeln!(s, "cup,{kp},{ki},dropped,8.0,4.0,").unwrap();
        }
    }
    std::fs::write(dir.join("results.csv"), s).unwrap();
    let files = plot::plot_path(&dir, None).unwrap();
    check_pair(&files, "sweep_cup", (1600, 1200), "up to 2 runs per cell");
    let svg = std::fs::read_to_string(dir.join("sweep_cup.svg")).unwrap();
    assert!(svg.contains("1/2"), "share held written in the cell");
    assert!(svg.contains(">\n7.25\n<"), "mean rise time (6.5+8)/2 written in the cell");
}

#[test]
fn stability_per_backend() {
    let (_keep, dir) = workdir("stability-backends");
    write_stability(&dir, &["mujoco", "rapier"]);
    let files = plot::plot_path(&dir, None).unwrap();
    check_pair(&files, "stability", (1100, 260 + 70 * 8), "Stability per backend and integrator");
    let svg = std::fs::read_to_string(dir.join("stability.svg")).unwrap();
    assert!(svg.contains("rapier / RK4") && svg.contains("mujoco / Euler"));
}

/// Issue 18: a trace whose force column is all NaN, or holds 1e308, is refused, not drawn.
#[test]
fn a_force_column_without_drawable_values_is_refused() {
    let (_keep, dir) = workdir("nonfinite");
    let trace = dir.join("trace.csv");
    // Column 6 is force_n.
    let with_force = |value: &dyn Fn(usize) -> String| {
        write_run(&dir, false, 100);
        let text = std::fs::read_to_string(&trace).unwrap();
        let lines: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| {
                if i == 0 {
                    return l.to_string();
                }
                let mut cells: Vec<String> = l.split(',').map(String::from).collect();
                cells[5] = value(i);
                cells.join(",")
            })
            .collect();
        std::fs::write(&trace, lines.join("\n") + "\n").unwrap();
    };
    with_force(&|_| "NaN".into());
    let e = plot::plot_path(&dir, None).unwrap_err().to_string();
    assert!(e.contains("trace.csv") && e.contains("`force_n` has no finite value"), "{e}");
    with_force(&|i| if i == 7 { "1e308".into() } else { "0.5".into() });
    let e = plot::plot_path(&dir, None).unwrap_err().to_string();
    assert!(e.contains("trace.csv:8:") && e.contains("force_n") && e.contains("beyond"), "{e}");
    with_force(&|i| if i == 7 { "inf".into() } else { "0.5".into() });
    assert!(plot::plot_path(&dir, None).is_err());
    with_force(&|_| "0.5".into());
    assert!(plot::plot_path(&dir, None).is_ok(), "a flat, finite trace draws");
}
