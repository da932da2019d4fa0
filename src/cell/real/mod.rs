//! The real cell: drivers for the UR5e, the Dynamixel MX-106 motors and the HYPERION interrogator.
//!
//! [`protocol`] holds the sans-IO codecs (bytes in, typed packets out, and back), for both the
//! client side (our drivers) and the device side (the virtual devices `tendril serve` exposes).
//! The IO layer around them: [`ur`] with [`dashboard`] (its preconditions), [`dxl`] with [`dxl_link`] (its IO thread), [`interrogator`]
//! (drivers), [`cell`] ([`RealCell`]), [`config`] (the scenario's `[hardware]` section), [`tcp`]
//! (connections), [`limits`] ([`LimitedCell`]), [`serve`] (virtual devices), [`urscript`] (the
//! motion program), [`realtime`] (scheduling of the control thread), [`latency`] (the tick-latency
//! benchmark).

pub mod cell;
pub mod config;
pub mod dashboard;
pub mod dxl;
pub mod dxl_link;
pub mod interrogator;
pub mod latency;
pub mod limits;
pub mod protocol;
pub mod realtime;
pub mod serve;
pub mod tcp;
pub mod ur;
pub mod urscript;

pub use cell::{RealCell, RealCellConfig, Watchdog};
pub use config::HardwareConfig;
pub use limits::{LimitedCell, SafetyLimits};
