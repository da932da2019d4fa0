//! The cell: where contact forces and wavelengths come from (simulation now, real drivers later).
pub mod physics;
