//! Control code shared by the simulated and the real cell.
pub mod estimate;
pub mod hysteresis;
