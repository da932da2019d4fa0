//! Where the closed loop oscillates or loses the object: each object's scenario over a
//! (Kp, Ki) grid with feedback on, refined adaptively ([`crate::sweep::refine`]): a coarse grid
//! first, then only the cells whose runs disagree.

use super::{run_all, set, write_csv};
use crate::sweep::contour::{Class, Contour, class_of};
use crate::sweep::refine::{Point, refine};
use std::path::{Path, PathBuf};
use tendril_config::Override;
use tendril_plot::gain_map::{GainMapRow, render};

/// Kp values tried [(°/s)/N]: a decade each side of the paper's 20.
pub const KP: [f64; 7] = [2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0];
/// Ki values tried [(°/s)/(N·s)]: from none through the paper's 0.05 to strongly integral.
pub const KI: [f64; 5] = [0.0, 0.05, 0.5, 5.0, 50.0];

/// How the map is refined.
#[derive(Debug, Clone)]
pub struct Refinement {
    /// The coarse grid's stride \[points\]; 1 runs every point.
    pub stride: usize,
    /// A figure's contour to follow besides held / dropped / oscillating.
    pub contour: Option<Contour>,
}

/// What the map writes for one point.
struct MapPoint {
    row: GainMapRow,
    ran: bool,
    beyond: Option<bool>,
}

/// Runs the map for each scenario, with `extra` applied to every run before the gains, writes
/// `gain_map.csv` (with whether each point ran or was filled in from its cell) and a chart per
/// object into `out`. A gain the scenario's bounds refuse is an error naming the key before
/// anything runs; so is a contour field the summary does not have, at the first run.
pub fn run(
    scenarios: &[PathBuf],
    kp: &[f64],
    ki: &[f64],
    extra: &[Override],
    refinement: &Refinement,
    out: &Path,
    threads: usize,
) -> anyhow::Result<Vec<PathBuf>> {
    let overrides = |p: Point| {
        let mut o = extra.to_vec();
        o.extend([set("controller.kp", kp[p.0]), set("controller.ki", ki[p.1]), set("feedback", true)]);
        o
    };
    for scenario in scenarios {
        for x in 0..kp.len() {
            for y in 0..ki.len() {
                tendril_config::load::<tendril_run::scenario::PickPlaceScenario>(scenario, &overrides((x, y)))?;
            }
        }
    }
    let mut points = Vec::new();
    let mut runs = 0;
    for scenario in scenarios {
        let mut object = String::new();
        let map = refine(kp.len(), ki.len(), refinement.stride, |batch| {
            let done = run_all(scenario, batch.iter().map(|&p| overrides(p)).collect(), threads)?;
            done.into_iter()
                .map(|r| {
                    object.clone_from(&r.summary.run.object);
                    class_of(&r.summary, refinement.contour.as_ref())
                })
                .collect::<anyhow::Result<Vec<Class>>>()
        })?;
        runs += map.runs();
        for (x, &kp) in kp.iter().enumerate() {
            for (y, &ki) in ki.iter().enumerate() {
                let known = map.get((x, y));
                let (outcome, oscillating, beyond) = known.class.clone();
                let row = GainMapRow { object: object.clone(), kp, ki, outcome, oscillating };
                points.push(MapPoint { row, ran: known.ran, beyond });
            }
        }
    }
    eprintln!("gain map: {runs} runs for {} points", points.len());
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let csv = out.join("gain_map.csv");
    let cells: Vec<Vec<String>> = points
        .iter()
        .map(|p| {
            let r = &p.row;
            let mut cells = vec![
                r.object.clone(),
                r.kp.to_string(),
                r.ki.to_string(),
                r.outcome.clone(),
                r.oscillating.to_string(),
            ];
            cells.push(p.ran.to_string());
            cells.push(p.beyond.map_or(String::new(), |b| b.to_string()));
            cells
        })
        .collect();
    write_csv(&csv, &["object", "kp", "ki", "outcome", "oscillating", "ran", "beyond_contour"], &cells)?;
    let mut files = vec![csv];
    files.extend(render(&points.into_iter().map(|p| p.row).collect::<Vec<_>>(), out)?);
    Ok(files)
}
