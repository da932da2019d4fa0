//! `convergence.csv` as each answer against refinement (x: halvings of the timestep or doublings of
//! the links from the default): four rows of panels (drop time, rise
//! time, largest fluctuation while moving, force RMSE against the finest setting), the left column
//! over the timestep at the default links, the right over the links at the default timestep; one
//! line per case, coloured by object, solid with feedback and dashed without.

use super::input::Table;
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One row of `convergence.csv`: one case at one numerical setting.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceRow {
    /// Physics backend.
    pub backend: String,
    /// Case label (`crimper on seed 1`).
    pub case: String,
    /// Object name.
    pub object: String,
    /// Force control kept on while the arm moves.
    pub feedback: bool,
    /// Seed.
    pub seed: u64,
    /// Setting label (`default`, `step/2`, `links x2`, `finest`...).
    pub setting: String,
    /// Physics timestep \[s\].
    pub timestep_s: f64,
    /// Finger links.
    pub segments: u32,
    /// `held`, `dropped` or `error`.
    pub outcome: String,
    /// Phase of the drop.
    pub drop_phase: Option<String>,
    /// Drop time after the arm starts \[s\].
    pub drop_time_s: Option<f64>,
    /// Rise time to 90 % of the setpoint \[s\].
    pub rise_time_s: Option<f64>,
    /// Largest fluctuation while moving \[%\].
    pub fluctuation_pct: Option<f64>,
    /// RMS difference of the true pad force from the finest setting's, up to the first drop \[N\].
    pub force_rmse_vs_finest_n: Option<f64>,
    /// Simulated seconds per wall second.
    pub sim_s_per_wall_s: f64,
    /// The run's error, if any.
    pub error: Option<String>,
    /// A produce item's flex grid, points per axis (absent for a rigid object).
    pub grid: Option<u32>,
    /// A produce item's flex degrees of freedom (`trilinear`, `quadratic`).
    pub dof: Option<String>,
    /// A produce item's largest peak contact pressure \[kPa\].
    pub peak_pressure_kpa: Option<f64>,
    /// A harvest's end (`harvested`, `stayed`, `slipped`, `dropped`).
    pub harvest: Option<String>,
    /// A harvest's largest stem tension, the pull the grip reached \[N\].
    pub max_stem_tension_n: Option<f64>,
}

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |v| format!("{v}"))
}

impl ConvergenceRow {
    /// The CSV header, in the order of [`ConvergenceRow::cells`]; the last five are a produce
    /// item's, optional when read.
    pub const HEADER: [&'static str; 21] = [
        "backend",
        "case",
        "object",
        "feedback",
        "seed",
        "setting",
        "timestep_s",
        "segments",
        "outcome",
        "drop_phase",
        "drop_time_s",
        "rise_time_s",
        "max_fluctuation_pct",
        "force_rmse_vs_finest_n",
        "sim_s_per_wall_s",
        "error",
        "produce_grid",
        "produce_dof",
        "peak_pressure_kpa",
        "harvest",
        "max_stem_tension_n",
    ];

    /// Columns every `convergence.csv` has (the produce ones came later).
    const REQUIRED: usize = 16;

    /// The row's CSV cells.
    pub fn cells(&self) -> Vec<String> {
        vec![
            self.backend.clone(),
            self.case.clone(),
            self.object.clone(),
            self.feedback.to_string(),
            self.seed.to_string(),
            self.setting.clone(),
            self.timestep_s.to_string(),
            self.segments.to_string(),
            self.outcome.clone(),
            self.drop_phase.clone().unwrap_or_default(),
            opt(self.drop_time_s),
            opt(self.rise_time_s),
            opt(self.fluctuation_pct),
            opt(self.force_rmse_vs_finest_n),
            self.sim_s_per_wall_s.to_string(),
            self.error.clone().unwrap_or_default(),
            self.grid.map_or_else(String::new, |g| g.to_string()),
            self.dof.clone().unwrap_or_default(),
            opt(self.peak_pressure_kpa),
            self.harvest.clone().unwrap_or_default(),
            opt(self.max_stem_tension_n),
        ]
    }
}

/// Reads `convergence.csv`.
pub fn read(path: &Path) -> Result<Vec<ConvergenceRow>, PlotError> {
    let t = Table::read(path)?;
    let c: Vec<usize> =
        ConvergenceRow::HEADER[..ConvergenceRow::REQUIRED].iter().map(|h| t.column(h)).collect::<Result<_, _>>()?;
    let extra: Vec<Option<usize>> =
        ConvergenceRow::HEADER[ConvergenceRow::REQUIRED..].iter().map(|h| t.optional_column(h)).collect();
    let rows = t
        .iter()
        .map(|r| {
            let text = |i: usize| r.text(c[i]).to_string();
            let nonempty = |i: usize| Some(text(i)).filter(|s| !s.is_empty());
            let count = |i: usize| text(i).parse::<u64>().map_err(|_| r.error(format!("`{}` is not a count", text(i))));
            Ok(ConvergenceRow {
                backend: text(0),
                case: text(1),
                object: text(2),
                feedback: r.bool(c[3])?,
                seed: count(4)?,
                setting: text(5),
                timestep_s: r.positive(c[6])?,
                segments: count(7)? as u32,
                outcome: r.one_of(c[8], &["held", "dropped", "error"])?,
                drop_phase: nonempty(9),
                drop_time_s: r.opt_f64(c[10])?,
                rise_time_s: r.opt_f64(c[11])?,
                fluctuation_pct: r.opt_f64(c[12])?,
                force_rmse_vs_finest_n: r.opt_f64(c[13])?,
                sim_s_per_wall_s: r.f64(c[14])?,
                error: nonempty(15),
                grid: extra[0].and_then(|i| r.text(i).parse().ok()),
                dof: extra[1].map(|i| r.text(i).to_string()).filter(|s| !s.is_empty()),
                peak_pressure_kpa: extra[2].map(|i| r.opt_f64(i)).transpose()?.flatten(),
                harvest: extra[3].map(|i| r.text(i).to_string()).filter(|s| !s.is_empty()),
                max_stem_tension_n: extra[4].map(|i| r.opt_f64(i)).transpose()?.flatten(),
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no rows to plot"));
    }
    Ok(rows)
}

/// Draws `convergence.png/.svg` in `out_dir`; returns the files written.
pub fn render(rows: &[ConvergenceRow], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    super::save(&Convergence { rows: rows.to_vec() }, out_dir, "convergence")
}

struct Convergence {
    rows: Vec<ConvergenceRow>,
}

type Metric = (&'static str, fn(&ConvergenceRow) -> Option<f64>);

const METRICS: [Metric; 4] = [
    ("drop time after the arm starts [s]", |r| r.drop_time_s),
    ("rise time to 90 % [s]", |r| r.rise_time_s),
    ("largest fluctuation while moving [%]", |r| r.fluctuation_pct),
    ("force RMSE vs the finest setting [N]", |r| r.force_rmse_vs_finest_n),
];

impl Convergence {
    fn default_row(&self) -> Option<&ConvergenceRow> {
        self.rows.iter().find(|r| r.setting == "default")
    }

    /// The series of one axis: per case, (x, row) over the settings on that axis, in x order.
    /// The timestep axis keeps the default links; the links axis keeps the default timestep.
    fn series(&self, links_axis: bool) -> Vec<(String, Vec<(f64, &ConvergenceRow)>)> {
        let Some(d) = self.default_row() else { return Vec::new() };
        let cases = super::grid::first_seen(self.rows.iter().map(|r| r.case.clone()));
        cases
            .into_iter()
            .map(|case| {
                let mut pts: Vec<(f64, &ConvergenceRow)> = self
                    .rows
                    .iter()
                    .filter(|r| r.case == case)
                    // A produce item's grid and degrees of freedom have no axis here: only the
                    // default's are drawn (the study's table holds the others).
                    .filter(|r| r.grid == d.grid && r.dof == d.dof)
                    .filter(|r| if links_axis { r.timestep_s == d.timestep_s } else { r.segments == d.segments })
                    .map(|r| (refinement(links_axis, d, r), r))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                (case, pts)
            })
            .collect()
    }

    fn colour(&self, object: &str) -> RGBColor {
        let objects = super::grid::first_seen(self.rows.iter().map(|r| r.object.clone()));
        let i = objects.iter().position(|o| o == object).unwrap_or(0);
        style::SERIES[i % style::SERIES.len()]
    }
}

/// How many halvings of the timestep (or doublings of the links) from the default `d` to `r`.
fn refinement(links_axis: bool, d: &ConvergenceRow, r: &ConvergenceRow) -> f64 {
    if links_axis {
        (f64::from(r.segments) / f64::from(d.segments)).log2()
    } else {
        (d.timestep_s / r.timestep_s).log2()
    }
}

impl Chart for Convergence {
    fn size(&self) -> (u32, u32) {
        (1300, 1500)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let backend = self.rows.first().map_or("", |r| r.backend.as_str());
        let root = root.titled(
            &format!("Convergence ({backend}): each answer against the timestep (left) and the finger links (right)"),
            (FONT, style::TITLE),
        )?;
        let (w, _) = root.dim_in_pixel();
        let (plots, key) = root.split_horizontally(w - 220);
        let panels = plots.split_evenly((METRICS.len(), 2));
        for (k, panel) in panels.iter().enumerate() {
            let (metric, links_axis) = (&METRICS[k / 2], k % 2 == 1);
            let series = self.series(links_axis);
            let xs: Vec<f64> = series.iter().flat_map(|(_, p)| p.iter().map(|(x, _)| *x)).collect();
            let ys: Vec<f64> = series.iter().flat_map(|(_, p)| p.iter().filter_map(|(_, r)| (metric.1)(r))).collect();
            let xhi = xs.iter().copied().fold(0.0_f64, f64::max).max(1.0);
            let yhi = ys.iter().copied().fold(0.0_f64, f64::max).max(1e-3) * 1.1;
            let Some(d) = self.default_row() else { continue };
            let (dt0, links0) = (d.timestep_s, f64::from(d.segments));
            let mut chart = ChartBuilder::on(panel)
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .caption(metric.0, (FONT, style::LABEL))
                .build_cartesian_2d(-0.25..xhi + 0.25, 0.0..yhi)?;
            chart
                .configure_mesh()
                .x_desc(if links_axis { "finger links (doubled)" } else { "timestep (halved)" })
                .axis_desc_style((FONT, style::SMALL))
                .label_style((FONT, style::SMALL))
                .x_labels(xhi as usize + 1)
                .x_label_formatter(&|v| {
                    let k = v.round();
                    if (v - k).abs() > 1e-6 {
                        String::new()
                    } else if links_axis {
                        style::num(links0 * k.exp2())
                    } else {
                        style::timestep(dt0 / k.exp2())
                    }
                })
                .y_label_formatter(&|v| style::num(*v))
                .draw()?;
            for (_, pts) in &series {
                let Some((_, first)) = pts.first() else { continue };
                let colour = self.colour(&first.object);
                let line: Vec<(f64, f64)> = pts.iter().filter_map(|(x, r)| (metric.1)(r).map(|y| (*x, y))).collect();
                if first.feedback {
                    chart.draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))?;
                } else {
                    chart.draw_series(DashedLineSeries::new(line.clone(), 6, 4, colour.stroke_width(2)))?;
                }
                chart.draw_series(line.iter().map(|p| Circle::new(*p, 3, colour.filled())))?;
            }
        }
        let objects = super::grid::first_seen(self.rows.iter().map(|r| r.object.clone()));
        let mut y = 60;
        for o in &objects {
            key.draw(&PathElement::new(vec![(10, y), (40, y)], self.colour(o).stroke_width(3)))?;
            key.draw(&Text::new(o.clone(), (48, y - 8), (FONT, style::LABEL).into_font()))?;
            y += 26;
        }
        key.draw(&Text::new("solid: feedback on", (10, y), (FONT, style::SMALL).into_font()))?;
        key.draw(&Text::new("dashed: feedback off", (10, y + 20), (FONT, style::SMALL).into_font()))?;
        key.draw(&Text::new("one line per seed", (10, y + 40), (FONT, style::SMALL).into_font()))?;
        Ok(())
    }
}
