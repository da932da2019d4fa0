//! [`PhysicsError`]: why the physics stopped or could not start; [`Divergence`]: what diverged.

/// Why the physics stopped or could not start.
#[derive(Debug, thiserror::Error)]
pub enum PhysicsError {
    /// A model template has a placeholder nobody filled (a bug between models/ and compose.rs).
    #[error("model template: placeholder {placeholder} has no value")]
    Template {
        /// The placeholder, e.g. `${k_bend}`.
        placeholder: String,
    },
    /// MuJoCo refused the assembled model.
    #[error("MuJoCo could not compile the scene: {message}")]
    Compile {
        /// MuJoCo's message.
        message: String,
    },
    /// The configuration is out of range.
    #[error("invalid scene configuration: key `{key}`: {reason}")]
    Config {
        /// Dotted key at fault.
        key: String,
        /// What is wrong.
        reason: String,
    },
    /// An actuator or arm input is not a finite number.
    #[error("input {what} is not finite: {value}")]
    BadInput {
        /// Which input.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A part of the scene (models/finger.xml, ...) could not be read from the models folder.
    #[error("{file}: cannot read this part of the scene: {cause}")]
    Part {
        /// The part's file.
        file: String,
        /// Why.
        cause: String,
    },
    /// An object's model file breaks the object contract (see [`super::object`]).
    #[error("object model {file}: {what}")]
    Object {
        /// The shipped object's name or the file.
        file: String,
        /// What is wrong or missing.
        what: String,
    },
    /// An element the scene needs is missing from the model (a bug between models/ and scene.rs).
    #[error("model has no {kind} named `{name}`")]
    Missing {
        /// Element kind.
        kind: &'static str,
        /// Its name.
        name: String,
    },
    /// The scene holds an element the backend cannot simulate (a model the rapier translation does
    /// not cover).
    #[error("the {backend} backend cannot simulate {what}")]
    Unsupported {
        /// The backend.
        backend: &'static str,
        /// The element and why.
        what: String,
    },
    /// The simulation diverged.
    #[error("simulation diverged at t = {time_s:.4} s: {cause}")]
    Diverged {
        /// Simulated time of the step that diverged \[s\].
        time_s: f64,
        /// What was detected.
        cause: Divergence,
    },
}

/// The symptom that stopped a diverging simulation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Divergence {
    /// A state value became NaN or infinite.
    #[error("non-finite {what}")]
    NonFinite {
        /// Which state array.
        what: &'static str,
    },
    /// MuJoCo raised a warning (it resets the state on bad accelerations, which would hide the blow-up).
    #[error("MuJoCo warning: {warning}")]
    Warning {
        /// The warning's name.
        warning: &'static str,
    },
    /// A contact is deeper than `physics.max_penetration_m` (a produce item's: or than its drop depth).
    #[error("contact {depth_m:.4} m deep between `{geom1}` and `{geom2}`")]
    Penetration {
        /// Penetration depth \[m\].
        depth_m: f64,
        /// First geom.
        geom1: String,
        /// Second geom.
        geom2: String,
    },
    /// A produce item's flex turned an element inside out: its elastic forces mean nothing from
    /// here on.
    #[error("the produce item's flex inverted (element {element}, volume {volume_m3:.3e} m³)")]
    FlexInverted {
        /// The tetrahedron that inverted.
        element: usize,
        /// Its signed volume now (its sign flipped) \[m³\].
        volume_m3: f64,
    },
    /// Kinetic energy beyond `physics.max_kinetic_energy_j`.
    #[error("kinetic energy {joules:.3e} J beyond the bound")]
    Energy {
        /// Kinetic energy \[J\].
        joules: f64,
    },
}
