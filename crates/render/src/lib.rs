#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod camera;

pub use camera::{Camera, FOLLOW_TIME_S, Follow, HAND_CAMERA};
use mujoco_rs::mujoco_c::{_mjtObjBase, mjtFrame, mjtJoint, mjtVisFlag};
use mujoco_rs::prelude::{MjData, MjModel};
use mujoco_rs::renderer::{MjRenderer, RendererError};
use mujoco_rs::wrappers::mj_visualization::{MjvCamera, MjvOption};
use std::sync::Arc;
use tendril_twin::frames::Snapshot;
use tendril_twin::physics::SceneModel;
use tendril_twin::physics::follow_camera::DEFAULT_VIEWPOINT;

/// Largest picture side \[px\] (and so the offscreen buffer's).
pub const MAX_SIDE: u32 = 4096;

/// How the scene is looked at.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// Width of the picture \[px\], 16 to [`MAX_SIDE`].
    pub width: u32,
    /// Height of the picture \[px\], 16 to [`MAX_SIDE`].
    pub height: u32,
    /// The camera: tracking (the default), fixed, the hand's or one of the model's.
    pub camera: Camera,
    /// Tracking and fixed camera: distance from the object \[m\].
    pub distance_m: f64,
    /// Tracking and fixed camera: azimuth \[°\].
    pub azimuth_deg: f64,
    /// Tracking and fixed camera: elevation \[°\] (negative: from above).
    pub elevation_deg: f64,
    /// Draw the contact forces as MuJoCo computes them for the state (arrows, 2 cm per newton).
    pub contact_forces: bool,
}

impl Default for View {
    /// 640 × 480, the tracking camera at the scene's [`DEFAULT_VIEWPOINT`] (0.35 m from the
    /// object, from 135° and 20° above): the grip and the finger around it fill the picture.
    fn default() -> Self {
        View {
            width: 640,
            height: 480,
            camera: Camera::Tracking,
            distance_m: DEFAULT_VIEWPOINT.distance_m,
            azimuth_deg: DEFAULT_VIEWPOINT.azimuth_deg,
            elevation_deg: DEFAULT_VIEWPOINT.elevation_deg,
            contact_forces: true,
        }
    }
}

impl View {
    /// Checks the view, naming what is wrong (`width`, `height`, `distance_m`, ...).
    pub fn check(&self) -> anyhow::Result<()> {
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if !(16..=MAX_SIDE).contains(&v) {
                anyhow::bail!("{name} {v}: must be a number of pixels from 16 to {MAX_SIDE}");
            }
        }
        if !(self.distance_m.is_finite() && self.distance_m > 0.0 && self.distance_m <= 100.0) {
            anyhow::bail!("distance {}: must be a number of metres in (0, 100]", self.distance_m);
        }
        if !self.azimuth_deg.is_finite() || !(-90.0..=90.0).contains(&self.elevation_deg) {
            anyhow::bail!("the azimuth must be finite and the elevation within [-90, 90] degrees");
        }
        Ok(())
    }
}

/// Draws states of one scene model offscreen.
///
/// Holds an OpenGL context (EGL): use it on the thread that made it.
pub struct SceneRenderer {
    scene: Arc<SceneModel>,
    model: Arc<MjModel>,
    data: MjData<Arc<MjModel>>,
    renderer: MjRenderer,
    camera: Camera,
    /// The free camera's azimuth at the start \[°\].
    azimuth_deg: f64,
    /// The arm's base body (the root of the hand's tree), which the tracking camera turns about.
    arm_base: usize,
    /// The tracking camera's look-at point.
    follow: Follow,
    /// Bearing of the look-at point from the arm's base in the first state drawn \[°\].
    start_bearing_deg: Option<f64>,
    /// Whether the free camera has been aimed (at the first rendered state).
    aimed: bool,
}

impl SceneRenderer {
    /// A renderer for `scene` as `view` says. Fails with what to install when the machine has no
    /// EGL driver, and with the choices (the model's cameras among them) when `view.camera` names
    /// a camera the model does not have.
    pub fn new(scene: &Arc<SceneModel>, view: &View) -> anyhow::Result<SceneRenderer> {
        view.check()?;
        // The run's model with what only the picture needs changed: the offscreen buffer's size,
        // the force arrows and the sensor pad's colour.
        let mut model: MjModel = (**scene.model()).clone();
        {
            let vis = model.vis_mut();
            vis.global.offwidth = vis.global.offwidth.max(view.width as i32);
            vis.global.offheight = vis.global.offheight.max(view.height as i32);
            // Contact force arrows: 2 cm per newton (the grip is a few newtons), thinner than default.
            vis.map.force = 0.02;
            vis.scale.forcewidth = 0.02;
        }
        dress_for_screen(&mut model, scene);
        let model = Arc::new(model);
        let camera = match &view.camera {
            Camera::Hand => MjvCamera::new_fixed(camera_id(&model, HAND_CAMERA)?),
            Camera::Model(name) => MjvCamera::new_fixed(camera_id(&model, name)?),
            Camera::Tracking | Camera::Fixed => {
                let mut cam = MjvCamera::new_free(&model);
                cam.distance = view.distance_m;
                cam.azimuth = view.azimuth_deg;
                cam.elevation = view.elevation_deg;
                cam
            }
        };
        let mut options = MjvOption::default();
        options.flags[mjtVisFlag::mjVIS_CONTACTFORCE as usize] = u8::from(view.contact_forces);
        options.frame = mjtFrame::mjFRAME_NONE as i32;
        let renderer = MjRenderer::builder()
            .width(view.width)
            .height(view.height)
            .camera(camera)
            .opts(options)
            .build(&model)
            .map_err(|e| no_gl(&e))?;
        let data = MjData::new(model.clone());
        let arm_base = model.body_rootid()[scene.hand_body()] as usize;
        Ok(SceneRenderer {
            arm_base,
            scene: scene.clone(),
            model,
            data,
            renderer,
            camera: view.camera.clone(),
            azimuth_deg: view.azimuth_deg,
            follow: Follow::new(FOLLOW_TIME_S),
            start_bearing_deg: None,
            aimed: false,
        })
    }

    /// Numbers of `qpos`, `qvel`, `ctrl` and `act` values a state of this scene has.
    pub fn state_sizes(&self) -> [usize; 4] {
        let m = self.model.ffi();
        [m.nq, m.nv, m.nu, m.na].map(|n| n as usize)
    }

    /// Draws `state`, the scene at cell time `time_s` \[s\], and returns the picture: width ×
    /// height × 3 bytes of RGB, the top row first. The tracking camera's look-at point follows the
    /// object from one call to the next by the cell time between them ([`Follow`]); the fixed one
    /// is aimed at the object in the first state drawn and stays there.
    pub fn render(&mut self, state: &Snapshot, time_s: f64) -> anyhow::Result<&[u8]> {
        let sizes = self.state_sizes();
        let given = [state.qpos.len(), state.qvel.len(), state.ctrl.len(), state.act.len()];
        if given != sizes {
            anyhow::bail!(
                "a state of {given:?} (qpos, qvel, ctrl, act) values, but the scene's model has {sizes:?}: \
                 the state is not of this scene"
            );
        }
        self.set_state(state);
        self.data.forward();
        match self.camera {
            Camera::Tracking => {
                // The look-at point follows the object, and the camera turns about the arm's base
                // as the object does: the view the arm gives at the start (the arm behind the
                // object) stays, instead of the arm's links swinging between camera and object.
                let lookat = self.follow.update(camera_target(&self.scene, &self.data), time_s);
                let base = self.data.xpos()[self.arm_base];
                let bearing = (lookat[1] - base[1]).atan2(lookat[0] - base[0]).to_degrees();
                let start = *self.start_bearing_deg.get_or_insert(bearing);
                let turned = (bearing - start + 540.0).rem_euclid(360.0) - 180.0;
                let camera = self.renderer.camera_mut();
                camera.lookat = lookat;
                camera.azimuth = self.azimuth_deg + turned;
            }
            Camera::Fixed if !self.aimed => {
                self.renderer.camera_mut().lookat = camera_target(&self.scene, &self.data);
                self.aimed = true;
            }
            _ => {}
        }
        self.renderer.sync_data(&mut self.data).map_err(|e| anyhow::anyhow!("cannot render: {e}"))?;
        self.renderer.render().map_err(|e| anyhow::anyhow!("cannot render: {e}"))?;
        self.renderer.rgb_flat().ok_or_else(|| anyhow::anyhow!("the renderer gave no RGB image"))
    }

    /// Sets `state` into the data, the free joints' and balls' quaternions renormalised (a
    /// recorded frame holds them in f32).
    fn set_state(&mut self, state: &Snapshot) {
        self.data.qpos_mut().copy_from_slice(&state.qpos);
        self.data.qvel_mut().copy_from_slice(&state.qvel);
        self.data.ctrl_mut().copy_from_slice(&state.ctrl);
        self.data.act_mut().copy_from_slice(&state.act);
        for j in 0..self.model.ffi().njnt as usize {
            let adr = self.model.jnt_qposadr()[j] as usize;
            let quat = match self.model.jnt_type()[j] {
                mjtJoint::mjJNT_FREE => adr + 3..adr + 7,
                mjtJoint::mjJNT_BALL => adr..adr + 4,
                _ => continue,
            };
            let q = &mut self.data.qpos_mut()[quat];
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm > 0.0 {
                q.iter_mut().for_each(|x| *x /= norm);
            }
        }
    }
}

/// Dresses `model`, a copy of `scene`'s, for the screen as `tendril render` and `tendril view`
/// show it: the sensor pad in orange and, in a scene without lights of its own (no table, so no
/// `models/table.xml` lights), a brighter headlight, as MuJoCo's default leaves the arm and the
/// hand dark.
pub fn dress_for_screen(model: &mut MjModel, scene: &SceneModel) {
    if model.ffi().nlight == 0 {
        let vis = model.vis_mut();
        vis.headlight.ambient = [0.35, 0.35, 0.35];
        vis.headlight.diffuse = [0.6, 0.6, 0.6];
    }
    for &g in scene.pad_geoms() {
        model.geom_rgba_mut()[g] = [1.0, 0.45, 0.0, 1.0];
    }
}

/// Where the free camera looks in `data`'s state: the object's grip, or the hand when the scene
/// has no object.
pub fn camera_target(scene: &SceneModel, data: &MjData<Arc<MjModel>>) -> [f64; 3] {
    match scene.object_grip_geom() {
        Some(g) => data.geom_xpos()[g],
        None => data.xpos()[scene.hand_body()],
    }
}

/// The id of the model's camera `name`, or an error listing the choices: tracking, fixed and the
/// cameras the model has.
fn camera_id(model: &MjModel, name: &str) -> anyhow::Result<usize> {
    model.name_to_id(_mjtObjBase::mjOBJ_CAMERA, name).ok_or_else(|| {
        let cameras = (0..model.ffi().ncam as usize).filter_map(|c| model.id_to_name(_mjtObjBase::mjOBJ_CAMERA, c));
        let choices: Vec<&str> = ["tracking", "fixed"].into_iter().chain(cameras).collect();
        anyhow::anyhow!("camera {name}: the scene has no such camera; the choices are {}", choices.join(", "))
    })
}

/// The error when no offscreen OpenGL context can be opened.
fn no_gl(e: &RendererError) -> anyhow::Error {
    let cause = match e {
        RendererError::GlutinError(g) => g.to_string(),
        other => other.to_string(),
    };
    anyhow::anyhow!(
        "cannot render: no offscreen OpenGL context through EGL ({cause}); install Mesa's EGL and \
         OpenGL drivers (Debian/Ubuntu: libegl1 libgl1-mesa-dri) or a GPU driver with EGL"
    )
}

#[cfg(test)]
mod tests {
    use super::View;

    #[test]
    fn a_bad_view_is_named() {
        assert!(View::default().check().is_ok());
        let narrow = View { width: 8, ..View::default() };
        assert!(narrow.check().unwrap_err().to_string().starts_with("width 8"));
        let far = View { distance_m: f64::NAN, ..View::default() };
        assert!(far.check().unwrap_err().to_string().contains("distance"));
        let under = View { elevation_deg: -100.0, ..View::default() };
        assert!(under.check().unwrap_err().to_string().contains("elevation"));
    }
}
