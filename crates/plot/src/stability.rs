//! `stability.csv` as a dot matrix: per integrator (and backend) the timesteps tried, coloured
//! by outcome, with the largest stable timestep ringed and labelled.

use super::input::Table;
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// One row of `stability.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityRow {
    /// Physics backend ("mujoco", ...).
    pub backend: String,
    /// Integrator name.
    pub integrator: String,
    /// Physics timestep \[s\].
    pub timestep_s: f64,
    /// "stable", "diverged", "penetration" or "lost_grasp".
    pub outcome: String,
}

/// The outcomes, their colours and legend text.
const OUTCOMES: [(&str, RGBColor, &str); 4] = [
    ("stable", style::GOOD, "stable"),
    ("penetration", style::WARN, "penetration"),
    ("lost_grasp", style::OTHER, "lost grasp"),
    ("diverged", style::BAD, "diverged"),
];

/// Reads `stability.csv` (columns `backend,integrator,timestep_s,outcome`).
pub fn read(path: &Path) -> Result<Vec<StabilityRow>, PlotError> {
    let t = Table::read(path)?;
    let (backend, integrator) = (t.column("backend")?, t.column("integrator")?);
    let (dt, outcome) = (t.column("timestep_s")?, t.column("outcome")?);
    let names: Vec<&str> = OUTCOMES.iter().map(|o| o.0).collect();
    let rows = t
        .iter()
        .map(|r| {
            Ok(StabilityRow {
                backend: r.text(backend).to_string(),
                integrator: r.text(integrator).to_string(),
                timestep_s: r.positive(dt)?,
                outcome: r.one_of(outcome, &names)?,
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no rows to plot"));
    }
    Ok(rows)
}

/// The largest timestep of `rows` such that it and every smaller timestep tried is stable
/// (a stable point past a failure is not trusted); None if the smallest already fails.
pub fn largest_stable(rows: &[&StabilityRow]) -> Option<f64> {
    let mut sorted: Vec<&&StabilityRow> = rows.iter().collect();
    sorted.sort_by(|a, b| a.timestep_s.total_cmp(&b.timestep_s));
    sorted.iter().take_while(|r| r.outcome == "stable").map(|r| r.timestep_s).last()
}

/// Draws `stability.png/.svg` in `out_dir`; returns the files written.
pub fn render(rows: &[StabilityRow], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let groups = super::grid::first_seen(rows.iter().map(|r| (r.backend.clone(), r.integrator.clone())));
    super::save(&Stability { rows: rows.to_vec(), groups }, out_dir, "stability")
}

struct Stability {
    rows: Vec<StabilityRow>,
    /// (backend, integrator) in order of appearance; the first is drawn at the top.
    groups: Vec<(String, String)>,
}

impl Stability {
    /// Row index from the bottom (the first group at the top).
    fn y(&self, r: &StabilityRow) -> f64 {
        let i = self.groups.iter().position(|(b, g)| *b == r.backend && *g == r.integrator).unwrap_or(0);
        (self.groups.len() - 1 - i) as f64
    }
}

impl Chart for Stability {
    fn size(&self) -> (u32, u32) {
        (1100, 260 + 70 * self.groups.len() as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let n = self.groups.len();
        let lo = self.rows.iter().map(|r| r.timestep_s).fold(f64::INFINITY, f64::min);
        let hi = self.rows.iter().map(|r| r.timestep_s).fold(0.0, f64::max);
        let one_backend = self.groups.iter().all(|g| g.0 == self.groups[0].0);
        let names: Vec<String> =
            self.groups.iter().rev().map(|(b, i)| if one_backend { i.clone() } else { format!("{b} / {i}") }).collect();
        let title = if one_backend {
            format!("Stability of the integrators ({}): timesteps tried and their outcome", self.groups[0].0)
        } else {
            "Stability per backend and integrator: timesteps tried and their outcome".to_string()
        };
        let root = root.titled(&title, (FONT, style::TITLE))?;
        let (w, _) = root.dim_in_pixel();
        let (plot, key) = root.split_horizontally(w - 230);
        let mut chart = ChartBuilder::on(&plot)
            .margin(16)
            .margin_right(30)
            .x_label_area_size(56)
            .y_label_area_size(if one_backend { 130 } else { 210 })
            .build_cartesian_2d(((lo / 1.6)..(hi * 1.6)).log_scale(), -0.5..n as f64 - 0.5)?;
        chart
            .configure_mesh()
            .y_max_light_lines(0)
            .x_desc("physics timestep (log scale)")
            .y_desc(if one_backend { "integrator" } else { "backend / integrator" })
            .axis_desc_style((FONT, style::AXIS))
            .label_style((FONT, style::LABEL))
            .x_label_formatter(&|v| style::timestep(*v))
            .y_labels(n + 1)
            .y_label_formatter(&|v| {
                super::grid::index_label(*v).and_then(|i| names.get(i).cloned()).unwrap_or_default()
            })
            .draw()?;
        // The key, outside the data so it hides no point.
        let mut y = 40;
        for (name, color, text) in OUTCOMES {
            let pts: Vec<(f64, f64)> =
                self.rows.iter().filter(|r| r.outcome == name).map(|r| (r.timestep_s, self.y(r))).collect();
            if pts.is_empty() {
                continue;
            }
            chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 9, color.filled())))?;
            key.draw(&Circle::new((20, y), 8, color.filled()))?;
            key.draw(&Text::new(text, (38, y - 8), (FONT, style::LABEL).into_font()))?;
            y += 28;
        }
        key.draw(&Circle::new((20, y), 12, BLACK.stroke_width(3)))?;
        key.draw(&Text::new("largest stable", (38, y - 17), (FONT, style::LABEL).into_font()))?;
        key.draw(&Text::new("timestep", (38, y + 1), (FONT, style::LABEL).into_font()))?;
        for (b, g) in &self.groups {
            let rows: Vec<&StabilityRow> = self.rows.iter().filter(|r| r.backend == *b && r.integrator == *g).collect();
            if let Some(dt) = largest_stable(&rows) {
                let y = self.y(rows[0]);
                chart.draw_series(std::iter::once(Circle::new((dt, y), 15, BLACK.stroke_width(3))))?;
                let font = TextStyle::from((FONT, style::SMALL).into_font()).pos(Pos::new(HPos::Center, VPos::Bottom));
                chart.plotting_area().draw(&Text::new(style::timestep(dt), (dt, y + 0.32), font))?;
            }
        }
        Ok(())
    }
}
