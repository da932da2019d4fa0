//! Settings chosen by the object (`[detector]`): a simulated object detector names the object's
//! class from the cell's camera view, and the class picks the force setpoint and the controller's
//! gains from a per-object table (the file `tendril tune` writes, [`crate::object_table`]).
//!
//! The detector's view is the twin's ground truth: the class is the scene's object (its label:
//! `object.name`, else the stem of `object.file`). The camera sees every object of the study whole, standing on the table in
//! front of the finger, so a segmentation render of the scene would return the same class; what
//! makes the detector imperfect is its error model, stated and seeded:
//! - a confusion matrix: the probability of each class being reported for each true class
//!   (`confusion`, or `accuracy` on the diagonal with the rest spread evenly);
//! - a miss rate: the detector reports nothing, and the cell uses the table's `fallback`
//!   settings, or the scenario's own when the table has none;
//! - a latency: the class arrives this long after the view is taken at home, and the task does
//!   not start to grow the finger before it does (the home phase lasts at least this long).
//!
//! The draw uses its own random stream seeded from the scenario's `seed`, so the sensor's noise is
//! the same with or without a detector, and a run is reproducible from its scenario.
//!
//! The detection is applied to the scenario as it is read ([`apply`], from
//! [`crate::scenario::PickPlaceScenario`]'s `prepare`): the class's keys replace the scenario's,
//! so everything downstream (the plan, the summary's setpoint and gains, the recorded effective
//! scenario) has the settings the run used; applying it again to that record changes nothing.

use super::object_table::ObjectTable;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;
use tendril_cell::MAX_PHASE_S;
use tendril_config::{Checker, Validate};
use tendril_twin::physics::ObjectConfig;

/// Rows of a confusion matrix must sum to 1 within this (rounding of a hand-written table).
pub const ROW_SUM_TOLERANCE: f64 = 1e-6;

/// Mixed into the scenario's seed for the detector's own stream (an arbitrary odd constant), so
/// it draws independently of the sensor's noise seeded with the same `seed`.
const STREAM: u64 = 0x9e37_79b9_7f4a_7c15;

/// The simulated detector (TOML `[detector]`; absent by default: the scenario's own settings).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DetectorConfig {
    /// The per-object table: each class's setpoint and controller keys (a TOML file, relative to
    /// the scenario; `tendril tune` writes one as `DIR/table.toml`; `scenarios/object-table.toml`).
    pub table: PathBuf,
    /// Probability of reporting the true class [-], the rest spread evenly over the table's other
    /// classes; used for every true class `confusion` does not list. 1: a perfect detector.
    #[serde(default = "one")]
    pub accuracy: f64,
    /// Per true class, the probability of each class being reported [-] (a row of the confusion
    /// matrix: `crimper = { crimper = 0.9, shampoo = 0.1 }`); each row sums to 1.
    #[serde(default)]
    pub confusion: BTreeMap<String, BTreeMap<String, f64>>,
    /// Probability that the detector reports nothing [-]: the table's `fallback` settings are used.
    #[serde(default)]
    pub miss_rate: f64,
    /// Time from the view at home to the class \[s\]: the finger does not grow before it. 0.2 s: a
    /// stated choice, a small convolutional detector on the cell's PC.
    #[serde(default = "default_latency")]
    pub latency_s: f64,
}

fn one() -> f64 {
    1.0
}

fn default_latency() -> f64 {
    0.2
}

/// What the detector reported for one run.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Detection {
    /// The scene's object (the true class).
    pub true_class: String,
    /// The class reported (`None`: a miss).
    pub reported: Option<String>,
    /// Whose settings the run used: the reported class, `fallback`, or `scenario` (a miss
    /// with no fallback in the table).
    pub settings: String,
    /// The latency \[s\].
    pub latency_s: f64,
}

impl DetectorConfig {
    /// The confusion row of `true_class` over `classes` (in their order): the given row, or
    /// `accuracy` on the diagonal and the rest spread evenly.
    pub fn row(&self, true_class: &str, classes: &[String]) -> Vec<f64> {
        if let Some(row) = self.confusion.get(true_class) {
            return classes.iter().map(|c| row.get(c).copied().unwrap_or(0.0)).collect();
        }
        let others = classes.iter().filter(|c| c.as_str() != true_class).count();
        classes
            .iter()
            .map(|c| {
                if c == true_class {
                    self.accuracy
                } else if others > 0 {
                    (1.0 - self.accuracy) / others as f64
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// One detection of `true_class` among `classes`, drawn from the stream of `seed`.
    pub fn draw(&self, seed: u64, true_class: &str, classes: &[String], fallback: bool) -> Detection {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ STREAM);
        self.draw_with(&mut rng, true_class, classes, fallback)
    }

    /// As [`DetectorConfig::draw`], from `rng` (many draws from one stream: the tests).
    pub fn draw_with(&self, rng: &mut impl Rng, true_class: &str, classes: &[String], fallback: bool) -> Detection {
        let missed = rng.random::<f64>() < self.miss_rate;
        let u: f64 = rng.random();
        let reported = (!missed).then(|| {
            let row = self.row(true_class, classes);
            let mut sum = 0.0;
            let pick = row.iter().position(|p| {
                sum += p;
                u < sum
            });
            // Rounding may leave u just above the row's sum: the last class with any weight.
            let pick = pick.or_else(|| row.iter().rposition(|&p| p > 0.0)).unwrap_or(0);
            classes[pick].clone()
        });
        let settings = match &reported {
            Some(c) => c.clone(),
            None if fallback => "fallback".into(),
            None => "scenario".into(),
        };
        Detection { true_class: true_class.into(), reported, settings, latency_s: self.latency_s }
    }
}

impl Validate for DetectorConfig {
    fn validate(&self, at: &mut Checker) {
        at.in_range("accuracy", self.accuracy, 0.0, 1.0);
        at.in_range("miss_rate", self.miss_rate, 0.0, 1.0);
        at.in_range("latency_s", self.latency_s, 0.0, MAX_PHASE_S);
        for (true_class, row) in &self.confusion {
            let key = format!("confusion.{true_class}");
            at.require(&key, row.values().all(|p| p.is_finite() && (0.0..=1.0).contains(p)), || {
                format!("every probability must lie in [0, 1], got {row:?}")
            });
            let sum: f64 = row.values().sum();
            at.require(&key, (sum - 1.0).abs() <= ROW_SUM_TOLERANCE, || {
                format!("the row's probabilities must sum to 1, they sum to {sum:.6}")
            });
        }
    }
}

/// Checks the detector against its table and the scene (keys under `detector.`): the table reads,
/// its rows are valid, it has the class of the scene's object, and the confusion matrix names
/// only its classes.
pub fn check(detector: &DetectorConfig, object_class: &str, at: &mut Checker) {
    let table = match ObjectTable::read(&detector.table) {
        Ok(t) => t,
        Err(reason) => {
            at.require("detector.table", false, || reason);
            return;
        }
    };
    for (key, reason) in table.faults() {
        at.require("detector.table", false, || format!("{}: {key}: {reason}", detector.table.display()));
    }
    let classes = table.class_names();
    at.require("detector.table", classes.iter().any(|c| c == object_class), || {
        format!(
            "{} has no class `{object_class}`, the object this scene holds (object.name or object.file); its classes: {}",
            detector.table.display(),
            classes.join(", ")
        )
    });
    for (true_class, row) in &detector.confusion {
        for class in std::iter::once(true_class).chain(row.keys()) {
            at.require(&format!("detector.confusion.{true_class}"), classes.contains(class), || {
                format!("`{class}` is not a class of {} ({})", detector.table.display(), classes.join(", "))
            });
        }
    }
}

/// Applies the detection to a scenario's table before it is read (see the module docs): the
/// detected class's keys (or the fallback's) replace the scenario's, and the home phase lasts at
/// least the latency. A table that cannot be read, or lacks the scene's class, is left alone:
/// validation reports it ([`check`]).
pub fn apply(scenario: &mut toml::Table) {
    let Some(detector) = scenario.get("detector").cloned() else { return };
    let Ok(detector) = detector.try_into::<DetectorConfig>() else { return };
    // The class is the object's label, as the summary names it: its name, else its file's stem.
    let Some(object) = scenario.get("object").cloned().and_then(|o| o.try_into::<ObjectConfig>().ok()) else {
        return;
    };
    let true_class = object.label();
    let true_class = true_class.as_str();
    let Ok(table) = ObjectTable::read(&detector.table) else { return };
    let classes = table.class_names();
    if !classes.iter().any(|c| c == true_class) {
        return;
    }
    let seed = scenario.get("seed").and_then(|s| tendril_config::seed::deserialize(s.clone()).ok()).unwrap_or(1);
    let detection = detector.draw(seed, true_class, &classes, table.fallback.is_some());
    let keys = match detection.reported.as_deref() {
        Some(class) => table.classes.get(class),
        None => table.fallback.as_ref(),
    };
    for (key, value) in keys.into_iter().flatten() {
        set_dotted(scenario, key, value.clone());
    }
    let settle_s = scenario.get("task").and_then(|t| t.get("settle_s")).and_then(toml::Value::as_float);
    let default_settle_s = tendril_control::task::TaskConfig::default().settle_s;
    if settle_s.unwrap_or(default_settle_s) < detector.latency_s {
        set_dotted(scenario, "task.settle_s", toml::Value::Float(detector.latency_s));
    }
}

/// Sets `dotted.key` in `table`, making the tables on the way.
fn set_dotted(table: &mut toml::Table, key: &str, value: toml::Value) {
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().unwrap_or(key);
    let mut here = table;
    for part in parts {
        let entry = here.entry(part).or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let toml::Value::Table(inner) = entry else { return };
        here = inner;
    }
    here.insert(last.into(), value);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn classes() -> Vec<String> {
        ["crimper", "shampoo", "hammer"].map(String::from).to_vec()
    }

    fn detector(confusion: &[(&str, &[(&str, f64)])], miss_rate: f64) -> DetectorConfig {
        DetectorConfig {
            table: PathBuf::from("t.toml"),
            accuracy: 1.0,
            confusion: confusion
                .iter()
                .map(|(t, row)| (t.to_string(), row.iter().map(|(c, p)| (c.to_string(), *p)).collect()))
                .collect(),
            miss_rate,
            latency_s: 0.2,
        }
    }

    #[test]
    fn many_draws_reproduce_the_confusion_matrix_and_the_miss_rate() {
        let d = detector(
            &[
                ("crimper", &[("crimper", 0.7), ("shampoo", 0.2), ("hammer", 0.1)]),
                ("hammer", &[("crimper", 0.05), ("hammer", 0.95)]),
            ],
            0.1,
        );
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let n = 100_000;
        for (truth, expected) in [("crimper", [0.7, 0.2, 0.1]), ("hammer", [0.05, 0.0, 0.95])] {
            let mut counts = [0usize; 3];
            let mut misses = 0;
            for _ in 0..n {
                match d.draw_with(&mut rng, truth, &classes(), true).reported {
                    Some(c) => counts[classes().iter().position(|k| *k == c).unwrap()] += 1,
                    None => misses += 1,
                }
            }
            // 4.5 standard deviations of a binomial proportion at n = 100 000: a false failure
            // about once in 150 000 runs of this test.
            let tol = |p: f64, m: usize| 4.5 * (p * (1.0 - p) / m as f64).sqrt() + 1e-12;
            let seen = n - misses;
            assert!((misses as f64 / n as f64 - 0.1).abs() <= tol(0.1, n), "miss rate {misses} of {n}");
            for (k, p) in expected.iter().enumerate() {
                let f = counts[k] as f64 / seen as f64;
                assert!((f - p).abs() <= tol(*p, seen), "{truth} → {}: {f} against {p}", classes()[k]);
            }
        }
    }

    #[test]
    fn an_accuracy_spreads_the_rest_evenly_and_a_draw_is_the_seeds() {
        let d = DetectorConfig { accuracy: 0.8, ..detector(&[], 0.0) };
        let row = d.row("shampoo", &classes());
        assert!(row.iter().zip([0.1, 0.8, 0.1]).all(|(a, b)| (a - b).abs() < 1e-12), "{row:?}");
        let a = d.draw(3, "shampoo", &classes(), false);
        assert_eq!(a, d.draw(3, "shampoo", &classes(), false), "the same seed, the same detection");
        let missed = DetectorConfig { miss_rate: 1.0, ..d.clone() };
        assert_eq!(missed.draw(3, "shampoo", &classes(), false).settings, "scenario");
        assert_eq!(missed.draw(3, "shampoo", &classes(), true).settings, "fallback");
    }

    #[test]
    fn a_row_that_does_not_sum_to_one_is_refused_by_its_key() {
        let d = detector(&[("crimper", &[("crimper", 0.7), ("shampoo", 0.2)])], 0.0);
        let mut at = Checker::default();
        at.section("detector", &d);
        let (key, reason) = at.into_first_error().unwrap();
        assert_eq!(key, "detector.confusion.crimper");
        assert!(reason.contains("sum to 1") && reason.contains("0.9"), "{reason}");
    }
}
