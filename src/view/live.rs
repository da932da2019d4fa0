//! The viewer window around the simulated cell: [`LiveCell`] is the [`SimCell`] as a [`Cell`] that,
//! after each control tick's physics, syncs MuJoCo's viewer with the sim's `MjData`, draws, reads
//! the keys and keeps the pace.

use super::keys::{self, Controls};
use super::pace::Pacer;
use super::{ViewError, ViewOptions};
use mujoco_rs::mujoco_c::mjtState;
use mujoco_rs::viewer::{MjViewer, egui};
use mujoco_rs::wrappers::mj_rendering::MjrRectangle;
use std::cell::RefCell;
use std::path::Path;
use std::rc::Rc;
use std::time::{Duration, Instant};
use tendril_cell::{Cell, CellCommand, CellError, CellState, GroundTruth, Lifecycle};
use tendril_control::task::Phase;
use tendril_run::runner::Outcome;
use tendril_run::trace::TraceRow;
use tendril_twin::sim::SimCell;

/// Wall time between two frames: 60 frames/s at most, whatever the speed factor.
pub const FRAME: Duration = Duration::from_micros(16_667);

/// What the on-screen panel shows and the keys set; shared by the run loop's hook, the cell and
/// the viewer's UI callback (all on the main thread).
#[derive(Debug, Clone, Default)]
pub struct Status {
    /// The last control tick.
    pub row: Option<TraceRow>,
    /// Force control during the arm's moves (the sequencer's setting).
    pub feedback: bool,
    /// What the keys have asked for.
    pub controls: Controls,
    /// Knocks applied so far.
    pub knocks: u32,
    /// Cell seconds per wall second.
    pub speed: f64,
    /// How the task ended, once it has.
    pub finished: Option<String>,
    /// The window's size in pixels, as the panel last saw it.
    pub window_px: Option<(usize, usize)>,
}

/// The panel's text: time and phase, the forces (true, estimate, setpoint), feedback, speed.
pub fn panel_text(s: &Status) -> String {
    let mut text = String::new();
    match &s.row {
        Some(r) => {
            text += &format!("t = {:7.2} s   phase: {}\n", r.time_s, r.phase.name());
            text += &format!("true force   {:6.2} N\n", r.true_force_n);
            text += &format!("estimate     {:6.2} N\n", r.force_n);
            text += &format!("setpoint     {:6.2} N\n", r.setpoint_n);
            text += &format!("controller   {}\n", if r.controller_on { "on" } else { "off" });
        }
        None => text += &format!("t = {:7.2} s   phase: {}\n", 0.0, Phase::Home.name()),
    }
    text += &format!("feedback while moving: {}\n", if s.feedback { "on" } else { "off" });
    text += &format!("speed {}x{}", s.speed, if s.controls.paused { "   PAUSED" } else { "" });
    if s.knocks > 0 {
        text += &format!("   knocks: {}", s.knocks);
    }
    if let Some(end) = &s.finished {
        text += &format!("\ntask ended: {end}");
    }
    text
}

/// The simulated cell shown live in MuJoCo's viewer (see the module docs).
pub struct LiveCell {
    sim: SimCell,
    viewer: MjViewer,
    status: Rc<RefCell<Status>>,
    speed: f64,
    pacer: Option<Pacer>,
    opened: Instant,
    deadline: Option<Instant>,
    last_frame: Option<Instant>,
    frames: u64,
    /// The sim's state before a sync, to undo a reset from the viewer (Backspace).
    state: Vec<f64>,
    reset_refused: bool,
}

/// The state a viewer sync may write back (MuJoCo's integration state).
const STATE: u32 = mjtState::mjSTATE_INTEGRATION as u32;

impl LiveCell {
    /// Opens the viewer window for `sim`'s scene on `display` (its name for messages). A window
    /// that cannot be opened (no server behind the display, no OpenGL) is a
    /// [`ViewError::Window`], never a panic.
    pub fn open(sim: SimCell, display: &str, name: &str, opts: &ViewOptions) -> Result<LiveCell, ViewError> {
        let model = viewer_model(&sim);
        let title = format!("tendril view: {name}");
        // mujoco-rs panics in a few set-up failures (no usable GL configuration): caught here and
        // reported in one line like the errors, without the panic message and backtrace.
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| {}));
        let built = std::panic::catch_unwind(|| MjViewer::builder().window_name(title).build_passive(&model));
        std::panic::set_hook(previous);
        let window_error = |cause: String| ViewError::Window { display: display.to_string(), cause };
        let mut viewer = match built {
            Ok(Ok(v)) => v,
            Ok(Err(e)) => return Err(window_error(error_chain(&e))),
            Err(panic) => return Err(window_error(panic_text(panic.as_ref()))),
        };
        let status = Rc::new(RefCell::new(Status { speed: opts.speed, ..Status::default() }));
        viewer.add_ui_callback({
            let status = status.clone();
            move |ui, _| panel(ui, &mut status.borrow_mut())
        });
        let opened = Instant::now();
        Ok(LiveCell {
            state: vec![0.0; model.state_size(STATE)],
            sim,
            viewer,
            status,
            speed: opts.speed,
            pacer: None,
            opened,
            deadline: opts.seconds.map(|s| opened + Duration::from_secs_f64(s)),
            last_frame: None,
            frames: 0,
            reset_refused: false,
        })
    }

    /// The shared status (for the run loop's hook).
    pub fn status(&self) -> Rc<RefCell<Status>> {
        self.status.clone()
    }

    /// Frames drawn so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Wall time since the window opened \[s\].
    pub fn wall_s(&self) -> f64 {
        self.opened.elapsed().as_secs_f64()
    }

    /// Records how the task ended, for the panel.
    pub fn finished(&mut self, outcome: Outcome, error: Option<&str>) {
        let text = match (outcome, error) {
            (Outcome::Error, e) => format!("error: {}", e.unwrap_or("unknown")),
            (other, _) => other.name().to_string(),
        };
        self.status.borrow_mut().finished = Some(text);
    }

    /// Keeps the final state on screen until the window closes, the time limit passes or an
    /// operator stop (Ctrl-C); the mouse can still move the camera. Knocks and pause no longer
    /// apply (the task is over).
    pub fn hold(&mut self) -> Result<(), ViewError> {
        while self.stop_reason().is_none() {
            self.frame(true)?;
            std::thread::sleep(FRAME);
        }
        Ok(())
    }

    /// Saves the window's last frame as a PNG file at `path`.
    ///
    /// The viewer draws into a double-buffered window and swaps; the frame on screen is then the
    /// front buffer, which a second MuJoCo render context on the viewer's (still current) OpenGL
    /// context reads back.
    pub fn screenshot(&mut self, path: &Path) -> Result<(), ViewError> {
        let failed = |cause: String| ViewError::Screenshot { path: path.to_path_buf(), cause };
        self.draw().map_err(|e| failed(e.to_string()))?;
        let model = viewer_model(&self.sim);
        // SAFETY: `draw` made the viewer's OpenGL context current on this thread (the viewer
        // leaves it current after rendering), and it stays current until this context drops at the
        // end of this function.
        let mut context = unsafe { mujoco_rs::wrappers::mj_rendering::MjrContext::new(&model) };
        // The window's buffer MuJoCo reads (the back buffer of a double-buffered window, which
        // after the swap still holds the frame on Mesa; undefined by OpenGL elsewhere).
        context.window();
        let Some((w, h)) = self.status.borrow().window_px.filter(|&(w, h)| w > 0 && h > 0) else {
            return Err(failed("the window has no pixels".into()));
        };
        let rect = MjrRectangle { left: 0, bottom: 0, width: w as i32, height: h as i32 };
        let mut rgb = vec![0u8; w * h * 3];
        context.read_pixels(Some(&mut rgb), None, &rect).map_err(|e| failed(e.to_string()))?;
        // OpenGL's rows run bottom-up.
        let flipped: Vec<u8> = rgb.chunks_exact(w * 3).rev().flatten().copied().collect();
        crate::render::write_png(path, &flipped, w as u32, h as u32).map_err(|e| failed(format!("{e:#}")))
    }

    /// Why the session must end now, if it must.
    fn stop_reason(&self) -> Option<&'static str> {
        if !self.viewer.running() {
            Some("closing the viewer")
        } else if self.deadline.is_some_and(|d| Instant::now() >= d) {
            Some("the --seconds limit")
        } else if let Some(signal) = tendril_cell::interrupt::requested() {
            Some(tendril_cell::interrupt::name(signal))
        } else {
            None
        }
    }

    /// Syncs the viewer with the sim's data (the perturbation goes into it) and draws a frame
    /// when one is due (or always, with `force`); then applies the knocks asked for.
    fn frame(&mut self, force: bool) -> Result<(), ViewError> {
        self.sync();
        if force || self.last_frame.is_none_or(|t| t.elapsed() >= FRAME) {
            self.draw()?;
        }
        let knocks = self.status.borrow_mut().controls.take_knocks();
        if self.sim.lifecycle() == Lifecycle::Active {
            for _ in 0..knocks {
                if self.sim.knock().is_some() {
                    self.status.borrow_mut().knocks += 1;
                }
            }
        }
        Ok(())
    }

    /// Renders one frame (the viewer also reads its mouse and keys here, and runs the panel).
    fn draw(&mut self) -> Result<(), ViewError> {
        self.viewer.render().map_err(|e| ViewError::Window { display: "viewer".into(), cause: error_chain(&e) })?;
        self.last_frame = Some(Instant::now());
        self.frames += 1;
        Ok(())
    }

    /// Two-way sync of the viewer and the sim's `MjData`. A reset from the viewer would take the
    /// twin's clock back under the running task: it is undone (once with a note).
    fn sync(&mut self) {
        let Some(data) = self.sim.mujoco_data_mut() else { return };
        let time = data.time();
        data.read_state_into(STATE, &mut self.state);
        self.viewer.sync_data(data);
        if data.time() != time {
            // The buffer came from this data a moment ago: the same model, the same size.
            let _ = data.set_state(&self.state, STATE);
            self.viewer.sync_data(data);
            if !self.reset_refused {
                self.reset_refused = true;
                eprintln!("tendril: view: the viewer's reset does not apply to a running task (restart the command)");
            }
        }
    }

    /// After the physics reached cell time `time_s`: frames, keys and pause until the tick is
    /// due on the wall clock.
    fn show(&mut self, time_s: f64) -> Result<(), CellError> {
        let stopped = |signal: &'static str| CellError::Stopped { signal, time_s };
        let origin = self.opened;
        if self.pacer.is_none() {
            self.pacer = Some(Pacer::new(self.speed, origin.elapsed(), time_s));
        }
        loop {
            self.frame(false).map_err(|e| CellError::Device { device: "viewer".into(), cause: e.to_string() })?;
            if let Some(reason) = self.stop_reason() {
                return Err(stopped(reason));
            }
            let now = origin.elapsed();
            let paused = self.status.borrow().controls.paused;
            let pacer = self.pacer.as_mut().expect("set above");
            if paused {
                pacer.restart(now, time_s);
                std::thread::sleep(FRAME);
                continue;
            }
            let wait = pacer.wait(now, time_s);
            if wait.is_zero() {
                return Ok(());
            }
            let to_frame = self.last_frame.map_or(Duration::ZERO, |t| FRAME.saturating_sub(t.elapsed()));
            std::thread::sleep(wait.min(to_frame.max(Duration::from_millis(1))));
        }
    }
}

impl Cell for LiveCell {
    fn backend(&self) -> &str {
        self.sim.backend()
    }

    fn lifecycle(&self) -> Lifecycle {
        self.sim.lifecycle()
    }

    fn configure(&mut self) -> Result<(), CellError> {
        self.sim.configure()
    }

    fn activate(&mut self) -> Result<(), CellError> {
        self.sim.activate()
    }

    fn deactivate(&mut self) -> Result<(), CellError> {
        self.sim.deactivate()
    }

    fn read(&mut self) -> Result<CellState, CellError> {
        self.sim.read()
    }

    fn write(&mut self, command: &CellCommand) -> Result<(), CellError> {
        self.sim.write(command)
    }

    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError> {
        self.sim.wait_until(time_s)?;
        self.show(time_s)
    }

    fn ground_truth(&self) -> Option<GroundTruth> {
        self.sim.ground_truth()
    }

    fn phase_started(&mut self, phase: Phase, time_s: f64) {
        self.sim.phase_started(phase, time_s);
    }

    fn sample_is_new(&self) -> bool {
        self.sim.sample_is_new()
    }
}

/// Distance of the viewer's free camera from the object at the start \[m\] (MuJoCo's free camera
/// stands 1.5 model extents away).
pub const CAMERA_DISTANCE_M: f64 = 0.6;

/// The model the viewer draws: the sim's, with its free camera on the object's grip at the start
/// (from 135° azimuth, 20° above, as `tendril render`) and dressed as `tendril render` dresses it
/// ([`tendril_render::dress_for_screen`]). Only what the viewer draws differs; the sim keeps its
/// own model. mujoco-rs's viewer gives no handle on its camera after it opens, so the view cannot
/// move it: the scene's `follow` camera (`]`, or the side panel's camera menu) follows the object.
fn viewer_model(sim: &SimCell) -> mujoco_rs::prelude::MjModel {
    let shared = sim.model();
    let start = tendril_twin::physics::Scene::new(shared.clone());
    let mut model = (**shared.model()).clone();
    model.stat_mut().center = tendril_render::camera_target(shared, start.data());
    model.stat_mut().extent = CAMERA_DISTANCE_M / 1.5;
    let render = crate::render::RenderOptions::default();
    let vis = model.vis_mut();
    vis.global.azimuth = render.azimuth_deg as f32;
    vis.global.elevation = render.elevation_deg as f32;
    tendril_render::dress_for_screen(&mut model, shared);
    model
}

/// The panel (top right): the status and buttons for the key actions; reads the keys.
fn panel(ui: &mut egui::Ui, status: &mut Status) {
    let ctx = ui.ctx().clone();
    let size = ctx.viewport_rect().size() * ctx.pixels_per_point();
    status.window_px = Some((size.x.round() as usize, size.y.round() as usize));
    if !ctx.egui_wants_keyboard_input() {
        let pressed: Vec<egui::Key> = ctx.input(|i| {
            i.events
                .iter()
                .filter_map(|e| match e {
                    egui::Event::Key { key, pressed: true, repeat: false, .. } => Some(*key),
                    _ => None,
                })
                .collect()
        });
        for action in pressed.into_iter().filter_map(keys::action) {
            status.controls.apply(action);
        }
    }
    egui::Window::new("tendril").anchor(egui::Align2::RIGHT_TOP, [-8.0, 8.0]).resizable(false).show(&ctx, |ui| {
        ui.monospace(panel_text(status));
        ui.horizontal(|ui| {
            let pause = if status.controls.paused { "Resume" } else { "Pause" };
            for (label, action) in [
                (pause, keys::Action::TogglePause),
                ("Feedback", keys::Action::ToggleFeedback),
                ("Knock", keys::Action::Knock),
            ] {
                let button = ui.button(label);
                if button.clicked() {
                    status.controls.apply(action);
                }
                // A focused button would also take Space as a click: the key would act twice.
                if button.has_focus() {
                    button.surrender_focus();
                }
            }
        });
        let help: Vec<String> = keys::HELP.iter().map(|(k, what)| format!("{k}: {what}")).collect();
        ui.small(format!(
            "{}; double-click a body, then Ctrl + Alt + drag: pull it; ]: the camera that follows the object, \
             Esc: the free camera",
            help.join(", ")
        ));
    });
}

/// An error and its causes in one line.
fn error_chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text += &format!(": {s}");
        source = s.source();
    }
    without_source_paths(&text.replace('\n', " "))
}

/// `text` without winit's "os error at /path/file.rs:LINE: " prefixes (where in winit's source the
/// error arose means nothing to a user).
fn without_source_paths(text: &str) -> String {
    const MARK: &str = "os error at ";
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find(MARK) {
        out += &rest[..at];
        let after = &rest[at + MARK.len()..];
        // The location ends at ".rs:LINE: ".
        match after.find(".rs:").and_then(|p| after[p + 4..].find(": ").map(|q| p + 4 + q + 2)) {
            Some(end) => rest = &after[end..],
            None => {
                out += MARK;
                rest = after;
            }
        }
    }
    out + rest
}

/// A caught panic's message, in one line.
fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    let text = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "the viewer failed to start".into());
    text.replace('\n', " ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(phase: Phase) -> TraceRow {
        TraceRow {
            time_s: 12.5,
            phase,
            true_force_n: 1.234,
            fbg1_nm: 1550.0,
            fbg2_nm: 1551.0,
            force_n: 1.2,
            force_uncompensated_n: 1.2,
            over_range: false,
            setpoint_n: 1.5,
            controller_on: true,
            controller_output_deg_s: 0.0,
            growth_motor_rad: 0.0,
            twine_motor_rad: 0.0,
            object_height_m: 0.1,
            slip_speed_m_s: 0.0,
            grip_force_n: 2.0,
            tool_load_n: 3.4,
            array: Default::default(),
            produce: None,
        }
    }

    #[test]
    fn the_panel_shows_the_forces_phase_and_settings() {
        let mut s = Status { row: Some(row(Phase::Transfer)), feedback: true, speed: 2.0, ..Status::default() };
        let text = panel_text(&s);
        for part in
            ["12.50 s", "phase: transfer", "true force     1.23 N", "estimate       1.20 N", "setpoint       1.50 N"]
        {
            assert!(text.contains(part), "{part:?} not in\n{text}");
        }
        assert!(text.contains("feedback while moving: on") && text.contains("speed 2x"), "{text}");
        assert!(!text.contains("PAUSED") && !text.contains("knocks"), "{text}");
        s.controls.paused = true;
        s.knocks = 2;
        s.feedback = false;
        s.finished = Some("held".into());
        let text = panel_text(&s);
        for part in ["PAUSED", "knocks: 2", "feedback while moving: off", "task ended: held"] {
            assert!(text.contains(part), "{part:?} not in\n{text}");
        }
    }

    #[test]
    fn before_the_first_tick_the_panel_shows_home() {
        assert!(panel_text(&Status::default()).contains("phase: home"));
    }

    #[test]
    fn errors_and_panics_read_in_one_line() {
        assert_eq!(panic_text(&"no usable\nGL config"), "no usable GL config");
        assert_eq!(panic_text(&String::from("boom")), "boom");
        assert_eq!(panic_text(&42), "the viewer failed to start");
        let io = std::io::Error::other("line one\nline two");
        assert_eq!(error_chain(&io), "line one line two");
        assert_eq!(
            without_source_paths(
                "event loop failed: os error at /src/winit/linux/mod.rs:788: Failed to open connection"
            ),
            "event loop failed: Failed to open connection"
        );
        assert_eq!(without_source_paths("os error at nowhere"), "os error at nowhere");
    }
}
