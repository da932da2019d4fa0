//! The FBG forward model (simulation side): true force and temperature at the sensor in, the two
//! peak wavelengths the interrogator reports out.
//!
//! ```text
//! N ─ clamp to range (uvula bottoms out) ─ PI hysteresis ─ backbone k1·n + k2·n² + k3·n³ ─┐
//! T ─ lag τ1 ─ K_T1·(T1 − T_ref) ─────────────────────────────────────────────────────────+─ λ1
//! T ─ lag τ2 ─ K_T2·(T2 − T_ref) ─────────────────────────────────────────────────────────── λ2
//!                                         interrogator: noise + 1 pm quantization, or spectra + centroid
//! ```

mod config;
mod sensor;
mod spectral;
mod thermal;

pub use config::{InterrogatorConfig, InterrogatorMode, SensorConfig, SpectralConfig};
pub use sensor::FbgSensor;
pub use spectral::{SpectralInterrogator, centroid, line_spectrum};
pub use thermal::ThermalLag;
