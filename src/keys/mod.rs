//! The scenario key reference, generated from the code (`tendril keys`): [`markdown`].

mod reference;
pub mod source;

pub use reference::markdown;
