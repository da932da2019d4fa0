#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

mod error;
mod files;
mod load;
mod magnitude;
mod overlay;
mod overrides;
pub mod seed;
mod validate;

pub use error::ScenarioError;
pub use files::write_atomically;
pub use load::{deserialize_section, from_str, from_table, load, read_text, section_error};
pub use magnitude::{MAX_MAGNITUDE, check_magnitudes};
pub use overlay::Overlay;
pub use overrides::{Override, apply_overrides};
pub use validate::{Checker, Validate};
