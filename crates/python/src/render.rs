//! [`Renderer`]: pictures of a running [`Session`]'s scene (what `GripEnv.render()` returns).

use crate::errors::run_error;
use crate::session::Session;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::sync::Arc;
use tendril_render::{Camera, SceneRenderer, View};
use tendril_twin::physics::SceneModel;

/// Draws a session's scene offscreen (MuJoCo's renderer through EGL), as `tendril render` draws
/// a recorded run: by default the tracking camera on the object, the pad in orange, the contact
/// forces as arrows.
/// Holds an OpenGL context: use it from the thread that made it.
#[pyclass(unsendable, module = "tendril._native")]
pub struct Renderer {
    inner: SceneRenderer,
    scene: Arc<SceneModel>,
    width: u32,
    height: u32,
}

#[pymethods]
impl Renderer {
    /// A renderer for `session`'s scene: `width` × `height` pixels, seen by `camera`: `"tracking"`
    /// (following the object through every phase), `"fixed"` (aimed at its start), `"hand"` (along
    /// the tool from the hand) or a camera of the model by name (`"follow"`: the model's camera
    /// aimed at the object from the arm's base link); the tracking and fixed cameras
    /// stand `distance_m` from the object at `azimuth_deg` and `elevation_deg`. Raises
    /// `RuntimeError` when the machine has no EGL driver (saying what to install) or the camera
    /// does not exist (naming the choices).
    #[new]
    #[pyo3(signature = (session, width = 640, height = 480, camera = "tracking", distance_m = 0.35, azimuth_deg = 135.0, elevation_deg = -20.0))]
    fn new(
        session: &Session,
        width: u32,
        height: u32,
        camera: &str,
        distance_m: f64,
        azimuth_deg: f64,
        elevation_deg: f64,
    ) -> PyResult<Renderer> {
        let scene = session.scene();
        let camera = Camera::parse(camera);
        let view = View { width, height, camera, distance_m, azimuth_deg, elevation_deg, ..View::default() };
        let inner = SceneRenderer::new(&scene, &view).map_err(run_error)?;
        Ok(Renderer { inner, scene, width, height })
    }

    /// Whether `session` runs the scene this renderer was made for (a reset may change the object).
    fn draws(&self, session: &Session) -> bool {
        Arc::ptr_eq(&self.scene, &session.scene())
    }

    /// `(width, height)` of the pictures \[px\].
    #[getter]
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The session's current state as RGB bytes (height × width × 3, the top row first), or
    /// `None` when the physics keeps no MuJoCo state to draw.
    fn render<'py>(&mut self, py: Python<'py>, session: &Session) -> PyResult<Option<Bound<'py, PyBytes>>> {
        if !self.draws(session) {
            return Err(run_error(anyhow::anyhow!(
                "this renderer was made for another scene: make a new one for this session"
            )));
        }
        let Some((state, time_s)) = session.snapshot() else { return Ok(None) };
        let rgb = self.inner.render(&state, time_s).map_err(run_error)?;
        Ok(Some(PyBytes::new(py, rgb)))
    }
}
