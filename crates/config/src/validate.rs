//! Range checks on deserialised scenarios, reported by dotted key.

/// Something that can check its own values after deserialisation.
///
/// Implementations call the [`Checker`] methods with their field names and descend into
/// nested sections with [`Checker::section`], so errors carry the full dotted path.
pub trait Validate {
    /// Records every out-of-range value in `at`.
    fn validate(&self, at: &mut Checker);

    /// Prepares the parsed table of a file of this type before it is deserialised (after the
    /// `--set` overrides): resolves paths relative to `file`, fills defaults that depend on other
    /// keys. Nothing by default.
    fn prepare(_table: &mut toml::Table, _file: &std::path::Path)
    where
        Self: Sized,
    {
    }
}

/// Collects validation errors under a dotted key prefix.
#[derive(Debug, Default)]
pub struct Checker {
    prefix: Vec<String>,
    errors: Vec<(String, String)>,
    /// Every bound checked, as (dotted key, the rule): what the scenario key reference shows.
    rules: Vec<(String, String)>,
}

impl Checker {
    fn key(&self, name: &str) -> String {
        let mut parts = self.prefix.clone();
        parts.push(name.to_string());
        parts.join(".")
    }

    /// Validates a nested section under `name`.
    pub fn section(&mut self, name: &str, inner: &impl Validate) {
        self.prefix.push(name.to_string());
        inner.validate(self);
        self.prefix.pop();
    }

    /// Records an error on key `name` unless `ok` holds.
    pub fn require(&mut self, name: &str, ok: bool, reason: impl FnOnce() -> String) {
        if !ok {
            let key = self.key(name);
            self.errors.push((key, reason()));
        }
    }

    fn rule(&mut self, name: &str, rule: String) {
        let key = self.key(name);
        self.rules.push((key, rule));
    }

    /// `value` must be finite and strictly positive.
    pub fn positive(&mut self, name: &str, value: f64) {
        self.rule(name, "> 0".into());
        self.require(name, value.is_finite() && value > 0.0, || format!("must be > 0, got {value}"));
    }

    /// `value` must be finite and not negative.
    pub fn non_negative(&mut self, name: &str, value: f64) {
        self.rule(name, ">= 0".into());
        self.require(name, value.is_finite() && value >= 0.0, || format!("must be >= 0, got {value}"));
    }

    /// `value` must be finite.
    pub fn finite(&mut self, name: &str, value: f64) {
        self.rule(name, "finite".into());
        self.require(name, value.is_finite(), || format!("must be a finite number, got {value}"));
    }

    /// `value` must lie in `[lo, hi]`.
    pub fn in_range(&mut self, name: &str, value: f64, lo: f64, hi: f64) {
        self.rule(name, format!("{} to {}", compact(lo), compact(hi)));
        self.require(name, value.is_finite() && (lo..=hi).contains(&value), || {
            format!("must be between {lo} and {hi}, got {value}")
        });
    }

    /// The first error recorded, as (dotted key, reason).
    pub fn into_first_error(self) -> Option<(String, String)> {
        self.errors.into_iter().next()
    }

    /// Every bound checked so far, as (dotted key, rule: `> 0`, `>= 0`, `finite`, `LO to HI`),
    /// whether the value met it or not. Checks that [`Checker::require`] makes with a reason of
    /// their own are not listed.
    pub fn rules(&self) -> &[(String, String)] {
        &self.rules
    }

    /// Every error recorded, as (dotted key, reason).
    pub fn errors(&self) -> &[(String, String)] {
        &self.errors
    }
}

/// A bound as a reader wants it: `0.001`, `10000`, `1e-300` (not 300 zeros).
fn compact(x: f64) -> String {
    if x != 0.0 && !(1e-4..1e7).contains(&x.abs()) { format!("{x:e}") } else { format!("{x}") }
}
