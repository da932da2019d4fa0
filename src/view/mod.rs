//! The twin live in MuJoCo's interactive viewer (`tendril view`).
//!
//! The run is the one `tendril run` makes (a [`tendril_run::session::Session`] on a [`tendril_twin::sim::SimCell`])
//! with the simulated cell wrapped in a `LiveCell`: after the physics reaches each control tick,
//! the live cell syncs the viewer with the sim's own `MjData` (the viewer's mouse perturbation
//! comes back into it as forces on the next steps), draws a frame when one is due and waits until
//! the tick is due on the wall clock at the chosen speed ([`pace`]). Between ticks the view hands
//! each tick's row to the on-screen panel and applies the feedback key to the session.
//!
//! - [`display`]: whether there is a display to open a window on.
//! - `keys` (with the `viewer` feature): the keys and what they ask of the run.
//! - [`pace`]: cell time against wall time at a speed factor.
//! - `live` (with the `viewer` feature): the viewer, the wrapped cell and the panel.
//!
//! The viewer is the `viewer` feature ([`crate::features`]); a build without it keeps the view's
//! options and errors, and [`view`] says how to build it.

pub mod display;
#[cfg(feature = "viewer")]
pub mod keys;
#[cfg(feature = "viewer")]
pub mod live;
pub mod pace;

#[cfg(feature = "viewer")]
pub use live::LiveCell;
use std::path::PathBuf;
use tendril_run::runner::Outcome;
use tendril_run::scenario::PickPlaceScenario;
#[cfg(feature = "viewer")]
use tendril_run::session::{Action, Session};
#[cfg(feature = "viewer")]
use tendril_twin::physics::{Backend, SceneModel};

/// Why the viewer could not show the run.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// Neither `DISPLAY` nor `WAYLAND_DISPLAY` is set.
    #[error(
        "no display: DISPLAY and WAYLAND_DISPLAY are unset, and the live viewer needs a window \
         (on a machine without one: `tendril run` the scenario, then `tendril render` its run folder)"
    )]
    NoDisplay,
    /// The window (or its OpenGL context) could not be created.
    #[error("cannot open the viewer window on the {display}: {cause}")]
    Window {
        /// The display tried.
        display: String,
        /// What went wrong.
        cause: String,
    },
    /// The scenario runs on a backend without a MuJoCo state to show.
    #[error("physics.backend = \"{0}\": the live viewer shows MuJoCo's state; use physics.backend = \"mujoco\"")]
    Backend(&'static str),
    /// The screenshot could not be taken or written.
    #[error("--screenshot {path}: {cause}")]
    Screenshot {
        /// The file asked for.
        path: PathBuf,
        /// What went wrong.
        cause: String,
    },
}

/// How to show the run.
#[derive(Debug, Clone)]
pub struct ViewOptions {
    /// Cell seconds per wall second (1: real time).
    pub speed: f64,
    /// Close the window after this many wall seconds (`None`: when the user closes it).
    pub seconds: Option<f64>,
    /// Save the last frame shown as a PNG file.
    pub screenshot: Option<PathBuf>,
}

/// What the session showed.
#[derive(Debug, Clone)]
pub struct ViewReport {
    /// How the task ended (an early close of the window is an `error` outcome: the task did not
    /// complete).
    pub outcome: Outcome,
    /// The error that ended the task, if any (the window closed, the time limit).
    pub error: Option<String>,
    /// Cell time reached \[s\].
    pub cell_time_s: f64,
    /// Control ticks run.
    pub ticks: usize,
    /// Frames drawn.
    pub frames: u64,
    /// Wall time the window was open \[s\].
    pub wall_s: f64,
}

/// Runs `scenario` on the twin in the live viewer until the window closes (or `opts.seconds`
/// pass): the task once, then its final state on screen. Fails before any window when there is
/// no display, the scenario's backend has no MuJoCo state or the screenshot's folder is missing.
#[cfg(feature = "viewer")]
pub fn view(scenario: &PickPlaceScenario, opts: &ViewOptions) -> anyhow::Result<ViewReport> {
    let spec = scenario.scene_spec();
    if spec.physics.backend != Backend::Mujoco {
        return Err(ViewError::Backend(spec.physics.backend.name()).into());
    }
    if let Some(path) = &opts.screenshot {
        // Checked before the window opens, not found out when it closes.
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
        if !dir.is_dir() {
            let cause = format!("{}: no such folder", dir.display());
            return Err(ViewError::Screenshot { path: path.clone(), cause }.into());
        }
    }
    let display = display::current_display().ok_or(ViewError::NoDisplay)?;
    let model = SceneModel::build(&spec)?;
    let cell = scenario.sim_cell(model);
    let mut live = LiveCell::open(cell, &display, &scenario.name, opts)?;
    let plan = scenario.control_plan();
    let status = live.status();
    status.borrow_mut().feedback = plan.feedback;
    let mut session = Session::start(&mut live, &plan, plan.controller.build(), None);
    while let Some(row) = session.step(Action::Controller) {
        let mut s = status.borrow_mut();
        if s.controls.take_feedback_switch() {
            session.set_feedback(!session.feedback());
        }
        s.row = Some(row);
        s.feedback = session.feedback();
    }
    let (report, _) = session.finish();
    live.finished(report.outcome, report.error.as_deref());
    live.hold()?;
    if let Some(path) = &opts.screenshot {
        live.screenshot(path)?;
    }
    Ok(ViewReport {
        outcome: report.outcome,
        error: report.error,
        cell_time_s: report.cell_time_s,
        ticks: report.rows.len(),
        frames: live.frames(),
        wall_s: live.wall_s(),
    })
}

/// A build without the `viewer` feature: the error that says how to build it.
#[cfg(not(feature = "viewer"))]
pub fn view(_scenario: &PickPlaceScenario, _opts: &ViewOptions) -> anyhow::Result<ViewReport> {
    Err(crate::features::Feature::Viewer.missing("tendril view"))
}
