//! The data that crosses the seam between the cell (sim or real) and the shared control code.

use serde::{Deserialize, Serialize};

/// One interrogator sample: the two FBG peak wavelengths as the interrogator reports them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Wavelengths {
    /// FBG1 (near 1540 nm, under the uvula: strain + temperature), in nm.
    pub fbg1_nm: f64,
    /// FBG2 (near 1550 nm, strain-free in the tube: temperature only), in nm.
    pub fbg2_nm: f64,
}

impl Default for Wavelengths {
    /// No sample: both peaks NaN.
    fn default() -> Self {
        Wavelengths { fbg1_nm: f64::NAN, fbg2_nm: f64::NAN }
    }
}
