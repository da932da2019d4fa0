//! `[produce]`: a produce item's properties within their literature range, the harvest's stem,
//! and the flex's numerical settings.

use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// The parametrisation of a flex's degrees of freedom (`flexcomp dof`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Dof {
    /// Three translations at each corner of the item's bounding box (24 degrees of freedom):
    /// stretch, compression and shear.
    Trilinear,
    /// Three translations at each corner, edge, face and the centre of the box (81): bending
    /// modes too.
    Quadratic,
}

impl Dof {
    /// The name as MJCF and scenarios write it.
    pub fn name(self) -> &'static str {
        match self {
            Dof::Trilinear => "trilinear",
            Dof::Quadratic => "quadratic",
        }
    }
}

/// Stiffness of the stem between the plant and the fruit's top \[N/m\]: 300 N/m, a stated choice.
/// The stem and the plant it hangs from yield a few centimetres before the stem lets go (a truss
/// swings when a fruit is pulled); 300 N/m gives way 3 cm at 10 N. Explicitly integrated, it must
/// stay well below `mass / timestep²` of the fruit's top half (12 g cherry tomato at 2.5 ms: 960
/// N/m).
pub const DEFAULT_STEM_STIFFNESS_N_M: f64 = 300.0;

/// `[produce]`: overrides of a produce item's file (each within its literature range, the file
/// holding the stated default), the harvest, and the flex's grid and degrees of freedom.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ProduceConfig {
    /// The flesh's apparent elastic modulus E \[Pa\] (the file's `produce_modulus_pa`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub modulus_pa: Option<f64>,
    /// Poisson's ratio, in (−1, 0.5) (the file's `produce_poisson`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub poisson: Option<f64>,
    /// Contact pressure above which the tissue bruises \[Pa\] (the file's `produce_bruise_pa`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bruise_pa: Option<f64>,
    /// Force at which the stem lets go \[N\] (the file's `produce_detach_n`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detach_n: Option<f64>,
    /// The item starts on its plant, hanging from its stem (a harvest), instead of standing on
    /// the table (a pick-and-place).
    pub harvest: bool,
    /// Stiffness of the stem and the plant behind it \[N/m\]: 300 N/m when the section is left out
    /// or does not give it ([`DEFAULT_STEM_STIFFNESS_N_M`], a stated choice).
    pub stem_stiffness_n_m: f64,
    /// Points per axis of the flex's grid, replacing the file's (a discretisation: the
    /// convergence study refines it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    /// The flex's degrees of freedom, replacing the file's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dof: Option<Dof>,
}

impl Default for ProduceConfig {
    fn default() -> Self {
        ProduceConfig {
            modulus_pa: None,
            poisson: None,
            bruise_pa: None,
            detach_n: None,
            harvest: false,
            stem_stiffness_n_m: DEFAULT_STEM_STIFFNESS_N_M,
            count: None,
            dof: None,
        }
    }
}

impl ProduceConfig {
    /// Whether the section is as by default (nothing to record).
    pub fn is_default(&self) -> bool {
        *self == ProduceConfig::default()
    }
}

impl Validate for ProduceConfig {
    fn validate(&self, at: &mut Checker) {
        if let Some(e) = self.modulus_pa {
            // Fruit flesh is 0.01-10 MPa; 1 Pa is softer than any gel, 1 GPa is wood's.
            at.in_range("modulus_pa", e, 1.0, 1e9);
        }
        if let Some(nu) = self.poisson {
            at.require("poisson", poisson_fault(nu).is_none(), || poisson_fault(nu).unwrap_or_default());
        }
        if let Some(b) = self.bruise_pa {
            // 1 Pa is far below any tissue's damage stress (tens of kPa); 1 GPa is wood's modulus.
            at.in_range("bruise_pa", b, 1.0, 1e9);
        }
        if let Some(d) = self.detach_n {
            // 1 mN is below any stem's hold; the finger's grip holds a few newtons by friction and
            // 1 kN is no fruit's stem.
            at.in_range("detach_n", d, 1e-3, 1000.0);
        }
        // Softer than 1 N/m lets the fruit hang metres below its plant; above 1e4 N/m the
        // explicit stem force is unstable at any step the cell runs.
        at.in_range("stem_stiffness_n_m", self.stem_stiffness_n_m, 1.0, 1e4);
        if let Some(n) = self.count {
            at.require("count", n >= 3, || format!("needs at least 3 points per axis, got {n}"));
            if n >= 3
                && let Some(fault) = grid_fault([n; 3])
            {
                at.require("count", false, || fault);
            }
        }
    }
}

/// Memory a compiled flex needs per vertex, model and data together, with the compiler's peak
/// \[bytes\]: measured 2.3 kB per vertex of a compiling process's peak on MuJoCo 3.17 (an
/// ellipsoid flex of 219 to 21 603 vertices), rounded up.
pub const BYTES_PER_VERTEX: f64 = 3000.0;

/// Why a Poisson's ratio cannot be an elastic solid's, if it cannot: `(-1, 0.5)` excluded ends
/// (0.5 is incompressible, where the bulk modulus and MuJoCo's elasticity are infinite).
pub fn poisson_fault(nu: f64) -> Option<String> {
    (!(nu > -1.0 && nu < 0.5)).then(|| {
        format!("Poisson's ratio must lie in (-1, 0.5), got {nu}: 0.5 is incompressible, -1 and below unstable")
    })
}

/// Why a modulus cannot be an elastic solid's, if it cannot.
pub fn modulus_fault(e: f64) -> Option<String> {
    (!(e > 0.0 && e.is_finite())).then(|| format!("must be a positive modulus in Pa, got {e}"))
}

/// Free memory of this machine \[bytes\] (`MemAvailable` of `/proc/meminfo`; `None` elsewhere).
fn available_memory_bytes() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Vertices of a flexcomp of `shape` with `count` points per axis: the surface of the grid (the
/// shell MuJoCo keeps for an ellipsoid or cylinder), an upper bound.
pub fn vertices_of(count: [u32; 3]) -> f64 {
    let [x, y, z] = count.map(f64::from);
    let inner = |n: f64| (n - 2.0).max(0.0);
    x * y * z - inner(x) * inner(y) * inner(z)
}

/// Why a grid of `count` points per axis cannot be built on this machine, if it cannot.
pub fn grid_fault(count: [u32; 3]) -> Option<String> {
    if count.iter().any(|&n| n < 3) {
        return Some(format!("every axis needs at least 3 points (a centre between two faces), got {count:?}"));
    }
    let bytes = vertices_of(count) * BYTES_PER_VERTEX;
    let free = available_memory_bytes()?;
    (bytes > free).then(|| {
        format!(
            "a grid of {count:?} points has about {:.0} vertices, which need about {:.1} GB; this machine has {:.1} GB free",
            vertices_of(count),
            bytes / 1e9,
            free / 1e9
        )
    })
}
