//! [`ModelCache`]: compiled scene models kept between sessions (a learning environment's resets
//! reuse the model instead of compiling it each episode).

use pyo3::prelude::*;

/// Compiled scene models, shared by the sessions given it; a model is compiled on first use
/// and kept while the cache lives (one per distinct scene: object, finger, physics settings).
#[pyclass(frozen, module = "tendril._native")]
#[derive(Default)]
pub struct ModelCache {
    pub(crate) inner: tendril_run::execute::ModelCache,
}

#[pymethods]
impl ModelCache {
    /// An empty cache.
    #[new]
    fn new() -> Self {
        ModelCache::default()
    }
}
