//! The real cell: drivers for the UR5e, the Dynamixel MX-106 motors and the HYPERION interrogator.
//!
//! [`protocol`] holds the sans-IO codecs (bytes in, typed packets out, and back), for both the
//! client side (our drivers) and the device side (the virtual devices `tendril serve` exposes).

pub mod protocol;
