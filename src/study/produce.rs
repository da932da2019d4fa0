//! `tendril chart produce`: the produce items squeezed between plates against Hertz, and for each
//! item the setpoints × feedback on/off × seeds of its pick-and-place (and of its harvest where it
//! has one): held, harvested, bruised; the window of setpoints that holds (or harvests) it without
//! bruising it, or "none" with the reason.

mod bump;

pub use bump::{BumpRow, FORCES_N as BUMP_FORCES_N, bump_test};

use super::{StudyRun, cell, run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::physics::{damage, hertz, plates};

/// The pick-and-place scenarios of the shipped produce items.
pub const PICKS: [&str; 4] =
    ["scenarios/cherry-tomato.toml", "scenarios/strawberry.toml", "scenarios/tomato.toml", "scenarios/basil.toml"];

/// The harvest scenarios (the items that have a stem to pull them off by).
pub const HARVESTS: [&str; 2] = ["scenarios/tomato-harvest.toml", "scenarios/strawberry-harvest.toml"];

/// The setpoints tried \[N\]: from a third of the paper's smallest (0.6 N) to two thirds of the
/// sensor's 4.69 N range.
pub const SETPOINTS_N: [f64; 8] = [0.2, 0.4, 0.6, 0.8, 1.0, 1.5, 2.0, 3.0];

/// The quick plan's setpoints \[N\].
pub const QUICK_SETPOINTS_N: [f64; 3] = [0.4, 1.0, 2.0];

/// Largest plate force the calibration chart draws \[N\]: beyond the pad's range, where a strip
/// link or the palm can still push.
pub const PLATES_MAX_FORCE_N: f64 = 5.0;

/// What the study runs.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Pick-and-place scenarios.
    pub picks: Vec<PathBuf>,
    /// Harvest scenarios.
    pub harvests: Vec<PathBuf>,
    /// Setpoints \[N\].
    pub setpoints: Vec<f64>,
    /// Seeds of every case.
    pub seeds: Vec<u64>,
}

impl Plan {
    /// The shipped items (or `scenarios`, sorted into picks and harvests by their
    /// `produce.harvest`), the full or the quick grid, `seeds` (default 1-3; quick 1).
    pub fn new(scenarios: &[PathBuf], quick: bool, seeds: &[u64]) -> anyhow::Result<Plan> {
        let (mut picks, mut harvests) = (Vec::new(), Vec::new());
        if scenarios.is_empty() {
            picks = PICKS.map(PathBuf::from).to_vec();
            harvests = HARVESTS.map(PathBuf::from).to_vec();
        } else {
            for s in scenarios {
                let loaded: PickPlaceScenario = tendril_config::load(s, &[])?;
                if loaded.produce.harvest { harvests.push(s.clone()) } else { picks.push(s.clone()) }
            }
        }
        let setpoints = if quick { QUICK_SETPOINTS_N.to_vec() } else { SETPOINTS_N.to_vec() };
        let seeds = if !seeds.is_empty() {
            seeds.to_vec()
        } else if quick {
            vec![1]
        } else {
            vec![1, 2, 3]
        };
        Ok(Plan { picks, harvests, setpoints, seeds })
    }
}

/// One run of the study, as `produce.csv` holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct ProduceRow {
    /// The scenario file's stem.
    pub scenario: String,
    /// The item (its object name).
    pub item: String,
    /// `pick` or `harvest`.
    pub task: &'static str,
    /// Setpoint \[N\].
    pub setpoint_n: f64,
    /// Force control while the arm moves.
    pub feedback: bool,
    /// Seed.
    pub seed: u64,
    /// `held`, `dropped` or `error`.
    pub outcome: String,
    /// A harvest's end (`harvested`, `stayed`, `slipped`, `dropped`).
    pub harvest: Option<String>,
    /// Whether some contact went above the bruise threshold.
    pub bruised: bool,
    /// Largest peak contact pressure \[kPa\].
    pub peak_pressure_kpa: Option<f64>,
    /// What pressed there.
    pub peak_at: String,
    /// The bruise threshold \[kPa\].
    pub bruise_threshold_kpa: Option<f64>,
    /// Largest area above it at once \[mm²\].
    pub bruise_area_mm2: Option<f64>,
    /// Time above it \[s\].
    pub time_above_s: Option<f64>,
    /// The bump's mean share of the pad's force while the item was held.
    pub bump_share: Option<f64>,
    /// Simulated seconds per CPU second.
    pub sim_s_per_cpu_s: f64,
    /// The run's error, if it ended on one.
    pub error: String,
}

impl ProduceRow {
    /// The columns of `produce.csv`.
    pub const HEADER: [&'static str; 17] = [
        "scenario",
        "item",
        "task",
        "setpoint_n",
        "feedback",
        "seed",
        "outcome",
        "harvest",
        "bruised",
        "peak_pressure_kpa",
        "peak_at",
        "bruise_threshold_kpa",
        "bruise_area_mm2",
        "time_above_s",
        "bump_share",
        "sim_s_per_cpu_s",
        "error",
    ];

    fn cells(&self) -> Vec<String> {
        vec![
            self.scenario.clone(),
            self.item.clone(),
            self.task.into(),
            format!("{}", self.setpoint_n),
            self.feedback.to_string(),
            self.seed.to_string(),
            self.outcome.clone(),
            self.harvest.clone().unwrap_or_default(),
            self.bruised.to_string(),
            cell(self.peak_pressure_kpa),
            self.peak_at.clone(),
            cell(self.bruise_threshold_kpa),
            cell(self.bruise_area_mm2),
            cell(self.time_above_s),
            cell(self.bump_share),
            format!("{}", self.sim_s_per_cpu_s),
            self.error.replace(['\n', '\r'], " "),
        ]
    }

    /// Whether the run did what the task asks: held to the release, or harvested.
    pub fn succeeded(&self) -> bool {
        match self.task {
            "harvest" => self.harvest.as_deref() == Some("harvested"),
            _ => self.outcome == "held",
        }
    }
}

/// The window of setpoints that does the task without bruising, for one item and task.
#[derive(Debug, Clone, PartialEq)]
pub struct Window {
    /// The item.
    pub item: String,
    /// `pick` or `harvest`.
    pub task: &'static str,
    /// The setpoints whose every feedback-on run did the task and bruised nothing \[N\].
    pub good_n: Vec<f64>,
    /// Why there is no window (empty when there is one).
    pub reason: String,
}

impl Window {
    /// The window as text: `0.4-1.0 N` (every setpoint tried between), `0.4, 1.5 N` (not all),
    /// or `none`.
    pub fn text(&self) -> String {
        match self.good_n.as_slice() {
            [] => "none".into(),
            [one] => format!("{one} N"),
            many => many.iter().map(|s| format!("{s}")).collect::<Vec<_>>().join(", ") + " N",
        }
    }
}

/// The windows of `rows` (feedback on, every seed), one per item and task, with `setpoints` the
/// setpoints tried.
pub fn windows(rows: &[ProduceRow], setpoints: &[f64]) -> Vec<Window> {
    let mut keys: Vec<(String, &'static str)> = Vec::new();
    for r in rows {
        if !keys.iter().any(|k| k.0 == r.item && k.1 == r.task) {
            keys.push((r.item.clone(), r.task));
        }
    }
    keys.into_iter()
        .map(|(item, task)| {
            let of = |sp: f64| -> Vec<&ProduceRow> {
                rows.iter().filter(|r| r.item == item && r.task == task && r.feedback && r.setpoint_n == sp).collect()
            };
            let done = |sp: f64| !of(sp).is_empty() && of(sp).iter().all(|r| r.succeeded());
            let clean = |sp: f64| of(sp).iter().all(|r| !r.bruised);
            let good_n: Vec<f64> = setpoints.iter().copied().filter(|&sp| done(sp) && clean(sp)).collect();
            let doing: Vec<f64> = setpoints.iter().copied().filter(|&sp| done(sp)).collect();
            let verb = if task == "harvest" { "harvested" } else { "held" };
            let reason = if !good_n.is_empty() {
                String::new()
            } else if doing.is_empty() {
                let bruised = setpoints.iter().filter(|&&sp| !clean(sp)).count();
                format!(
                    "no setpoint up to {} N {verb} it on every seed{}",
                    setpoints.iter().cloned().fold(0.0, f64::max),
                    if bruised > 0 { format!(" ({bruised} of the setpoints bruised it as well)") } else { String::new() }
                )
            } else {
                let first = doing[0];
                let peak = of(first).iter().filter_map(|r| r.peak_pressure_kpa).fold(0.0, f64::max);
                let at = of(first).iter().map(|r| r.peak_at.clone()).next().unwrap_or_default();
                let threshold = of(first).iter().filter_map(|r| r.bruise_threshold_kpa).next().unwrap_or(f64::NAN);
                format!(
                    "every setpoint that {verb} it bruised it: at {first} N the peak pressure is {peak:.0} kPa ({at}), above its {threshold:.0} kPa threshold"
                )
            };
            Window { item, task, good_n, reason }
        })
        .collect()
}

/// One sample of an item's calibrated plate test against Hertz, as `plates.csv` holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct PlateRow {
    /// The item.
    pub item: String,
    /// The plates' travel since first contact \[mm\].
    pub travel_mm: f64,
    /// Force on one plate \[N\].
    pub force_n: f64,
    /// Hertz's force at that travel \[N\].
    pub hertz_force_n: f64,
    /// The damage model's peak pressure for that force \[kPa\].
    pub peak_kpa: f64,
    /// Hertz's peak pressure at that travel \[kPa\].
    pub hertz_peak_kpa: f64,
    /// The damage model's contact radius for that force \[mm\].
    pub radius_mm: f64,
    /// Hertz's contact radius at that travel \[mm\].
    pub hertz_radius_mm: f64,
}

impl PlateRow {
    /// The columns of `plates.csv`.
    pub const HEADER: [&'static str; 8] =
        ["item", "travel_mm", "force_n", "hertz_force_n", "peak_kpa", "hertz_peak_kpa", "radius_mm", "hertz_radius_mm"];

    fn cells(&self) -> Vec<String> {
        vec![
            self.item.clone(),
            format!("{:.5}", self.travel_mm),
            format!("{:.5}", self.force_n),
            format!("{:.5}", self.hertz_force_n),
            format!("{:.3}", self.peak_kpa),
            format!("{:.3}", self.hertz_peak_kpa),
            format!("{:.5}", self.radius_mm),
            format!("{:.5}", self.hertz_radius_mm),
        ]
    }
}

/// An item's calibration, as `calibration.csv` holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationRow {
    /// The item.
    pub item: String,
    /// Its modulus \[Pa\].
    pub modulus_pa: f64,
    /// Hertz's radius against a plate \[mm\].
    pub radius_mm: f64,
    /// The contact stiffness found \[1/s²\].
    pub contact_stiffness: f64,
    /// Hertz's travel at the reference force \[mm\].
    pub reference_travel_mm: f64,
    /// The calibrated item's \[mm\].
    pub calibrated_travel_mm: f64,
    /// Largest deviation of the calibrated force from Hertz's between 0.3 and 3 N, as a fraction.
    pub max_force_error: f64,
}

impl CalibrationRow {
    /// The columns of `calibration.csv`.
    pub const HEADER: [&'static str; 7] = [
        "item",
        "modulus_pa",
        "radius_mm",
        "contact_stiffness_per_s2",
        "reference_travel_mm",
        "calibrated_travel_mm",
        "max_force_error_0_3_to_3_n",
    ];

    fn cells(&self) -> Vec<String> {
        vec![
            self.item.clone(),
            format!("{}", self.modulus_pa),
            format!("{:.3}", self.radius_mm),
            format!("{:.4e}", self.contact_stiffness),
            format!("{:.4}", self.reference_travel_mm),
            format!("{:.4}", self.calibrated_travel_mm),
            format!("{:.3}", self.max_force_error),
        ]
    }
}

/// The item of `scenario`, calibrated and squeezed to [`PLATES_MAX_FORCE_N`]: its curve against
/// Hertz's and its calibration's figures.
pub fn plate_test(scenario: &Path) -> anyhow::Result<(Vec<PlateRow>, CalibrationRow)> {
    let s: PickPlaceScenario = tendril_config::load(scenario, &[])?;
    let raw = s.object.model()?.produce.ok_or_else(|| anyhow::anyhow!("{}: not a produce item", scenario.display()))?;
    let item = raw.configured(&s.produce, s.object.mass_kg, s.object.friction)?;
    let physics = &s.physics;
    let cal = plates::calibrate(&item, physics)?;
    let samples = plates::compress(&item, physics, cal.contact_stiffness, PLATES_MAX_FORCE_N)?;
    let (r, e) = (plates::plate_radius_m(&item), plates::plate_modulus_pa(&item));
    let name = s.object.label();
    let rows: Vec<PlateRow> = samples
        .iter()
        .map(|p| {
            let patch = damage::patch_of(&item, [1.0, 0.0, 0.0], [0.0; 2], 1.0, p.force_n);
            let (peak, radius) = hertz::plates_patch(r, e, p.travel_m);
            PlateRow {
                item: name.clone(),
                travel_mm: p.travel_m * 1e3,
                force_n: p.force_n,
                hertz_force_n: hertz::plates_force_n(r, e, p.travel_m),
                peak_kpa: patch.peak_pa / 1e3,
                hertz_peak_kpa: peak / 1e3,
                radius_mm: patch.half_width_m * 1e3,
                hertz_radius_mm: radius * 1e3,
            }
        })
        .collect();
    let max_force_error = rows
        .iter()
        .filter(|p| (0.3..=3.0).contains(&p.hertz_force_n))
        .map(|p| (p.force_n / p.hertz_force_n - 1.0).abs())
        .fold(0.0, f64::max);
    let calibration = CalibrationRow {
        item: name,
        modulus_pa: item.properties.modulus_pa,
        radius_mm: r * 1e3,
        contact_stiffness: cal.contact_stiffness,
        reference_travel_mm: cal.reference_travel_m * 1e3,
        calibrated_travel_mm: cal.calibrated_travel_m * 1e3,
        max_force_error,
    };
    Ok((rows, calibration))
}

/// A study run as a row.
fn row(scenario: &Path, task: &'static str, run: &StudyRun) -> ProduceRow {
    let s = &run.summary;
    let p = s.produce.as_ref();
    ProduceRow {
        scenario: scenario.file_stem().map_or_else(String::new, |f| f.to_string_lossy().into()),
        item: s.run.object.clone(),
        task,
        setpoint_n: s.run.setpoint_n,
        feedback: s.run.feedback,
        seed: s.run.seed,
        outcome: s.outcome.clone(),
        harvest: p.and_then(|p| p.harvest.clone()),
        bruised: p.is_some_and(|p| p.bruised),
        peak_pressure_kpa: p.map(|p| p.peak_pressure_kpa),
        peak_at: p.map_or_else(String::new, |p| p.peak_at.clone()),
        bruise_threshold_kpa: p.map(|p| p.bruise_threshold_kpa),
        bruise_area_mm2: p.map(|p| p.bruise_area_mm2),
        time_above_s: p.map(|p| p.time_above_s),
        bump_share: p.and_then(|p| p.bump_share),
        sim_s_per_cpu_s: s.sim_s_per_cpu_s,
        error: s.error.clone().unwrap_or_default(),
    }
}

/// What the study wrote and found.
pub struct Outcome {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Each item's window.
    pub windows: Vec<Window>,
}

/// The plate and bump tests of each item of the plan, once per item: a harvest's item is usually
/// a pick's too, but a plan of harvests alone still needs its items' tests (it used to test only
/// the picks' items and fail on an empty `plates.csv`).
pub fn item_tests(plan: &Plan) -> anyhow::Result<(Vec<PlateRow>, Vec<CalibrationRow>, Vec<BumpRow>)> {
    let (mut plates, mut calibrations, mut bumps) = (Vec::new(), Vec::new(), Vec::new());
    let mut tested: Vec<String> = Vec::new();
    for scenario in plan.picks.iter().chain(&plan.harvests) {
        let s: PickPlaceScenario = tendril_config::load(scenario, &[])?;
        if tested.contains(&s.object.label()) {
            continue;
        }
        tested.push(s.object.label());
        let (rows, cal) = plate_test(scenario)?;
        plates.extend(rows);
        calibrations.push(cal);
        bumps.extend(bump_test(scenario)?);
    }
    Ok((plates, calibrations, bumps))
}

/// Runs the plan on `threads` workers; writes `calibration.csv`, `plates.csv`, `bump.csv`, `produce.csv`,
/// `produce_window.csv` and the charts in `out`.
pub fn run(plan: &Plan, out: &Path, threads: usize) -> anyhow::Result<Outcome> {
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let mut files = Vec::new();
    let (plates, calibrations, bumps) = item_tests(plan)?;
    let path = out.join("bump.csv");
    write_csv(&path, &BumpRow::HEADER, &bumps.iter().map(BumpRow::cells).collect::<Vec<_>>())?;
    files.push(path);
    let path = out.join("calibration.csv");
    write_csv(&path, &CalibrationRow::HEADER, &calibrations.iter().map(CalibrationRow::cells).collect::<Vec<_>>())?;
    files.push(path);
    let path = out.join("plates.csv");
    write_csv(&path, &PlateRow::HEADER, &plates.iter().map(PlateRow::cells).collect::<Vec<_>>())?;
    files.push(path.clone());
    files.extend(tendril_plot::produce::render_plates(&tendril_plot::produce::read_plates(&path)?, out)?);

    let mut rows = Vec::new();
    let tasks = plan.picks.iter().map(|s| (s, "pick")).chain(plan.harvests.iter().map(|s| (s, "harvest")));
    for (scenario, task) in tasks {
        let sets: Vec<Vec<tendril_config::Override>> = plan
            .setpoints
            .iter()
            .flat_map(|&sp| {
                [true, false].into_iter().flat_map(move |feedback| {
                    plan.seeds
                        .iter()
                        .map(move |&seed| vec![set("setpoint_n", sp), set("feedback", feedback), set("seed", seed)])
                })
            })
            .collect();
        for run in run_all(scenario, sets, threads)? {
            rows.push(row(scenario, task, &run));
        }
    }
    let path = out.join("produce.csv");
    write_csv(&path, &ProduceRow::HEADER, &rows.iter().map(ProduceRow::cells).collect::<Vec<_>>())?;
    files.push(path.clone());
    let windows = windows(&rows, &plan.setpoints);
    let path = out.join("produce_window.csv");
    let cells: Vec<Vec<String>> =
        windows.iter().map(|w| vec![w.item.clone(), w.task.into(), w.text(), w.reason.clone()]).collect();
    write_csv(&path, &["item", "task", "window", "reason"], &cells)?;
    files.push(path);
    files
        .extend(tendril_plot::produce::render_runs(&tendril_plot::produce::read_runs(&out.join("produce.csv"))?, out)?);
    Ok(Outcome { files, windows })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(item: &str, sp: f64, outcome: &str, bruised: bool) -> ProduceRow {
        ProduceRow {
            scenario: item.into(),
            item: item.into(),
            task: "pick",
            setpoint_n: sp,
            feedback: true,
            seed: 1,
            outcome: outcome.into(),
            harvest: None,
            bruised,
            peak_pressure_kpa: Some(if bruised { 200.0 } else { 50.0 }),
            peak_at: "pad_bump".into(),
            bruise_threshold_kpa: Some(150.0),
            bruise_area_mm2: Some(0.0),
            time_above_s: Some(0.0),
            bump_share: Some(0.5),
            sim_s_per_cpu_s: 5.0,
            error: String::new(),
        }
    }

    #[test]
    fn a_plan_of_harvests_alone_tests_its_items_between_plates() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let plan = Plan::new(&[root.join("scenarios/tomato-harvest.toml")], true, &[]).unwrap();
        assert!(plan.picks.is_empty() && plan.harvests.len() == 1);
        let (plates, calibrations, bumps) = item_tests(&plan).unwrap();
        assert!(!plates.is_empty(), "plates.csv gets the harvested item's plate test");
        assert_eq!(calibrations.len(), 1);
        assert_eq!(bumps.len(), BUMP_FORCES_N.len());
        assert!(bumps.iter().all(|b| b.item == calibrations[0].item));
    }

    #[test]
    fn a_window_holds_the_setpoints_that_hold_without_bruising_or_says_why_there_is_none() {
        let sp = [0.2, 0.6, 1.0, 2.0];
        let rows = vec![
            r("berry", 0.2, "dropped", false),
            r("berry", 0.6, "held", false),
            r("berry", 1.0, "held", false),
            r("berry", 2.0, "held", true),
            r("plum", 0.2, "dropped", false),
            r("plum", 0.6, "held", true),
            r("plum", 1.0, "held", true),
            r("plum", 2.0, "held", true),
            r("stone", 0.2, "dropped", false),
            r("stone", 2.0, "dropped", true),
        ];
        let w = windows(&rows, &sp);
        assert_eq!((w[0].good_n.clone(), w[0].text()), (vec![0.6, 1.0], "0.6, 1 N".to_string()));
        assert!(w[1].good_n.is_empty() && w[1].reason.contains("bruised it: at 0.6 N"), "{}", w[1].reason);
        assert!(w[2].reason.contains("no setpoint up to 2 N held it"), "{}", w[2].reason);
    }
}
