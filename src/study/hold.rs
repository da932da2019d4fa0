//! Holds of any length (`tendril chart hold`): the grip's and the twine motor's history over a long
//! grasp (`[task.hold]`). Given run folders (`--run DIR`, each with its `trace.csv`: the hour on
//! the twin, the hour on the real path), it draws them; given none, it runs the shortened form the
//! tests run (`scenarios/short-lift.toml`, a 150 s grasp, the strip creeping six times faster)
//! with the hold off and on, and draws both.

use super::set;
use std::path::{Path, PathBuf};
use tendril_config::Override;
use tendril_plot::panels::{Mark, Panel, Panels, Series};
use tendril_run::execute::{ModelCache, run_on_twin};
use tendril_run::scenario::PickPlaceScenario;

/// The shortened hour: a 150 s grasp with the strip's relaxation time 3 s instead of 19 (the
/// standard linear solid's retardation time 60 s instead of 380), so the travel runs out within the
/// grasp when the grip is held at the setpoint.
pub fn fast_creep() -> Vec<Override> {
    vec![set("task.grasp_s", 150), set("finger.relaxation_time_s", 3.0)]
}

/// Most points drawn per series (a long trace is thinned evenly; an hour at 100 Hz is 360 000 rows).
const MAX_POINTS: usize = 4000;

/// One run's history, read from its `trace.csv`.
struct History {
    name: String,
    /// (time [min], estimate [N], true pad force [N], grip force [N], twine motor [rad]).
    rows: Vec<[f64; 5]>,
}

fn read_history(name: &str, dir: &Path) -> anyhow::Result<History> {
    read_history_between(name, dir, f64::NEG_INFINITY, f64::INFINITY)
}

/// As [`read_history`], the rows from `from_min` to `to_min` only.
fn read_history_between(name: &str, dir: &Path, from_min: f64, to_min: f64) -> anyhow::Result<History> {
    let path = dir.join("trace.csv");
    let err = |e: csv::Error| anyhow::anyhow!("{}: {e}", path.display());
    let mut reader = csv::Reader::from_path(&path).map_err(err)?;
    let header = reader.headers().map_err(err)?.clone();
    let column = |name: &str| {
        header.iter().position(|h| h == name).ok_or_else(|| anyhow::anyhow!("{}: no column `{name}`", path.display()))
    };
    let columns = [
        column("time_s")?,
        column("force_n")?,
        column("true_force_n")?,
        column("grip_force_n")?,
        column("twine_motor_rad")?,
    ];
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(err)?;
        let mut row = [f64::NAN; 5];
        for (k, &c) in columns.iter().enumerate() {
            row[k] = record.get(c).and_then(|v| v.parse().ok()).unwrap_or(f64::NAN);
        }
        row[0] /= 60.0;
        if (from_min..=to_min).contains(&row[0]) {
            rows.push(row);
        }
    }
    let step = rows.len().div_ceil(MAX_POINTS).max(1);
    Ok(History { name: name.into(), rows: rows.into_iter().step_by(step).collect() })
}

/// Draws the runs' histories as `out/stem.png/.svg`: the force estimate, the true pad and grip
/// forces (where the cell has ground truth) and the twine motor against its travel's end; a run
/// longer than ten minutes gets two more rows, its first two minutes and its last (the release and
/// the re-wrap, at full resolution).
pub fn draw(runs: &[(String, PathBuf)], travel_rad: f64, out: &Path, stem: &str) -> anyhow::Result<Vec<PathBuf>> {
    let histories: Vec<History> = runs.iter().map(|(n, d)| read_history(n, d)).collect::<Result<_, _>>()?;
    let end = histories.iter().flat_map(|h| h.rows.last()).map(|r| r[0]).fold(0.0, f64::max);
    let mut windows = vec![(f64::NEG_INFINITY, f64::INFINITY, String::new())];
    if end > 10.0 {
        windows.push((0.0, 2.0, ", first 2 min".to_string()));
        windows.push((end - 1.0, end, ", last minute".to_string()));
    }
    let mut panels = Vec::new();
    let mut columns = 0;
    for (from, to, label) in &windows {
        let thinned: Vec<History> = if from.is_finite() {
            runs.iter().map(|(n, d)| read_history_between(n, d, *from, *to)).collect::<Result<_, _>>()?
        } else {
            histories.iter().map(|h| History { name: h.name.clone(), rows: h.rows.clone() }).collect()
        };
        let row = history_panels(&thinned, travel_rad, label);
        columns = row.len();
        panels.extend(row);
    }
    let chart = Panels { title: "A long grasp: the grip's and the twine motor's history".into(), panels, columns };
    Ok(tendril_plot::panels::render(&chart, out, stem)?)
}

/// One row of panels for `histories`: estimate, true forces (if any), twine.
fn history_panels(histories: &[History], travel_rad: f64, label: &str) -> Vec<Panel> {
    let series = |k: usize, suffix: &str| {
        histories
            .iter()
            .filter(|h| h.rows.iter().any(|r| r[k].is_finite()))
            .map(|h| Series {
                name: format!("{}{suffix}", h.name),
                points: h.rows.iter().map(|r| (r[0], r[k])).collect(),
                mark: Mark::Line,
            })
            .collect::<Vec<_>>()
    };
    let (start, end) = histories
        .iter()
        .flat_map(|h| h.rows.iter())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| (a.min(r[0]), b.max(r[0])));
    let mut twine = series(4, "");
    twine.push(Series {
        name: "end of the travel".into(),
        points: vec![(start, travel_rad), (end, travel_rad)],
        mark: Mark::Line,
    });
    let mut panels = vec![Panel {
        caption: format!("force estimate (eq. 8){label}"),
        x_desc: "time [min]".into(),
        y_desc: "[N]".into(),
        series: series(1, ""),
        y_range: None,
    }];
    let truth = series(2, ", pad");
    if !truth.is_empty() {
        let mut forces = truth;
        forces.extend(series(3, ", grip (strip and pad)"));
        panels.push(Panel {
            caption: format!("true forces on the object (twin){label}"),
            x_desc: "time [min]".into(),
            y_desc: "[N]".into(),
            series: forces,
            y_range: None,
        });
    }
    panels.push(Panel {
        caption: format!("twine motor{label}"),
        x_desc: "time [min]".into(),
        y_desc: "[rad]".into(),
        series: twine,
        y_range: Some((0.0, travel_rad * 1.1)),
    });
    panels
}

/// Runs the shortened hour on `scenario` with the hold off (`held/`) and on (`released/`) into
/// `out`, and draws both; returns the files and a line on each run.
pub fn run_fast_creep(scenario: &Path, out: &Path) -> anyhow::Result<(Vec<PathBuf>, String)> {
    let models = ModelCache::default();
    let mut runs = Vec::new();
    let mut text = String::new();
    let mut travel_rad = f64::NAN;
    for (name, hold) in [("held at the setpoint", false), ("released and re-wrapped", true)] {
        let mut o = fast_creep();
        o.push(set("task.hold.enabled", hold));
        let s: PickPlaceScenario = tendril_config::load(scenario, &o)?;
        travel_rad = s.gripper.twine_max_deg.to_radians();
        let dir = out.join(if hold { "released" } else { "held" });
        let (summary, _) = run_on_twin(&s, &models, Some(&dir))?;
        let h = summary.hold.unwrap_or_default();
        text += &format!(
            "{name}: {}{}; twine at most {:.0} % of its travel{}\n",
            summary.outcome,
            summary.drop_phase.as_ref().map_or(String::new(), |p| format!(" in the {p}")),
            100.0 * h.max_travel,
            h.travel_end_cell_time_s.map_or(String::new(), |t| format!(", at its end from {t:.1} s")),
        );
        runs.push((name.to_string(), dir));
    }
    let files = draw(&runs, travel_rad, out, "hold")?;
    Ok((files, text))
}
