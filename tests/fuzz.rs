//! A fuzz harness (issue 18): several hundred deterministically generated scenario, sweep and bench
//! CSV mutants, each checked in process through the library's own parse and validate path (as the
//! CLI calls it) on a thread of its own with a time limit, and a handful through the binary:
//! never a panic, never a hang, and never an acceptance of nonsense (a non-finite or huge number,
//! an unknown key) — which must be refused naming the key (or the CSV line) at fault.
//!
//! The mutants come from a fixed seed, so a failure names a mutant that reproduces.

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};
use tendril_config::ScenarioError;
use tendril_run::scenario::PickPlaceScenario;

use crate::common::cli::{stderr, tendril_command};

/// The longest a single in-process mutant may take; a hang fails the test instead of blocking it.
const LIMIT: Duration = Duration::from_secs(10);

/// xorshift64*: small, deterministic, good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Values no scenario key may take: non-finite, or beyond any quantity of the cell.
const NONSENSE: [&str; 9] =
    ["nan", "inf", "-inf", "1e300", "-1e300", "1e10", "-3e12", "1.7976931348623157e308", "-9223372036854775808"];

/// Values some keys take and others refuse: only no panic and no hang are required.
const ODD: [&str; 14] =
    ["0", "-1", "0.0", "-0.0", "1e-300", "\"\"", "\"x\"", "true", "[]", "[1.0, 2.0]", "{}", "1e9", "-1e9", "4.69"];

/// Keys of the pick-and-place scenario beyond those the shipped files set.
const KEYS: [&str; 40] = [
    "seed",
    "setpoint_n",
    "control_rate_hz",
    "feedback",
    "object.friction",
    "object.position_m",
    "controller.kp",
    "controller.ki",
    "controller.kd",
    "controller.max_speed_deg_s",
    "controller.derivative_filter_s",
    "task.settle_s",
    "task.growth_m",
    "task.growth_speed_m_s",
    "task.wrap_speed_deg_s",
    "task.wrap_contact_n",
    "task.wrap_timeout_s",
    "task.grasp_s",
    "task.lift_s",
    "task.release_s",
    "task.home_deg",
    "task.limits.max_speed_deg_s",
    "task.limits.max_accel_deg_s2",
    "slip.slip_fraction",
    "slip.lost_force_n",
    "slip.lost_hold_s",
    "slip.load_fall_fraction",
    "slip.lift_check_m",
    "wrist.noise_n",
    "wrist.sample_rate_hz",
    "estimator.range_n",
    "estimator.b_pm_per_n",
    "interrogator.sample_rate_hz",
    "interrogator.noise_pm",
    "environment.temperature_c",
    "physics.timestep_s",
    "physics.iterations",
    "physics.contact_dampratio",
    "physics.max_penetration_m",
    "finger.segments",
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `f` on a thread of its own: its result, or a failure naming `what` if it panics or takes
/// longer than [`LIMIT`].
fn bounded<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    let handle = std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    match rx.recv_timeout(LIMIT) {
        Ok(v) => {
            let _ = handle.join();
            v
        }
        Err(mpsc::RecvTimeoutError::Disconnected) => panic!("{what}: panicked"),
        Err(mpsc::RecvTimeoutError::Timeout) => panic!("{what}: no answer within {LIMIT:?} (a hang)"),
    }
}

/// Every dotted path to a non-table value in `table`.
fn leaves(table: &toml::Table, prefix: &str, out: &mut Vec<String>) {
    for (k, v) in table {
        let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
        match v {
            toml::Value::Table(t) => leaves(t, &key, out),
            _ => out.push(key),
        }
    }
}

/// Sets `key` (dotted) to `value` in `table`, creating sections; false if a parent is a value.
fn set(table: &mut toml::Table, key: &str, value: toml::Value) -> bool {
    let parts: Vec<&str> = key.split('.').collect();
    let (last, parents) = parts.split_last().unwrap();
    let mut node = table;
    for p in parents {
        let entry = node.entry(p.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
        match entry.as_table_mut() {
            Some(t) => node = t,
            None => return false,
        }
    }
    node.insert(last.to_string(), value);
    true
}

fn remove(table: &mut toml::Table, key: &str) {
    let parts: Vec<&str> = key.split('.').collect();
    let (last, parents) = parts.split_last().unwrap();
    let mut node = table;
    for p in parents {
        match node.get_mut(*p).and_then(|v| v.as_table_mut()) {
            Some(t) => node = t,
            None => return,
        }
    }
    node.remove(*last);
}

fn value(text: &str) -> toml::Value {
    format!("v = {text}").parse::<toml::Table>().unwrap().remove("v").unwrap()
}

/// What a mutant must do.
#[derive(Debug, Clone, PartialEq)]
enum Expect {
    /// Be refused, naming exactly this key.
    RefusedAt(String),
    /// Anything but a panic or a hang.
    NoPanic,
}

/// Deserialises and validates a scenario table as the CLI does after `--set`.
fn load_table(table: toml::Table, file: PathBuf) -> Result<(), ScenarioError> {
    tendril_config::from_table::<PickPlaceScenario>(table, &file).map(|_| ())
}

#[test]
fn scenario_mutants_are_refused_naming_the_key_and_never_hang() {
    let started = Instant::now();
    let mut rng = Rng(0x5EED_0018);
    let bases: Vec<(PathBuf, toml::Table)> = ["crimper", "hammer", "shampoo", "short-lift"]
        .iter()
        .map(|n| {
            let f = root().join(format!("scenarios/{n}.toml"));
            let t = std::fs::read_to_string(&f).unwrap().parse().unwrap();
            (f, t)
        })
        .collect();
    let (mut refused, mut total) = (0, 0);
    for i in 0..320 {
        let (file, base) = rng.pick(&bases).clone();
        let mut table = base.clone();
        let mut file_keys = Vec::new();
        leaves(&table, "", &mut file_keys);
        let key: String = if rng.below(2) == 0 { rng.pick(&file_keys).clone() } else { rng.pick(&KEYS).to_string() };
        let kind = rng.below(6);
        let expect = match kind {
            // A nonsensical number at one key.
            0 | 1 => {
                let mut text = *rng.pick(&NONSENSE);
                // The seed spans u64: a huge integer is a valid seed.
                if key == "seed" && !text.contains(['e', 'n', 'i', '.']) {
                    text = "1e300";
                }
                set(&mut table, &key, value(text));
                Expect::RefusedAt(key.clone())
            }
            // A nonsensical number inside an array value.
            2 => {
                let arr = ["task.home_deg", "object.position_m", "task.lift_deg"][rng.below(3)];
                let n = if arr == "object.position_m" { 2 } else { 6 };
                let mut items: Vec<String> = vec!["0.0".into(); n];
                items[rng.below(n)] = rng.pick(&NONSENSE).to_string();
                set(&mut table, arr, value(&format!("[{}]", items.join(", "))));
                Expect::RefusedAt(arr.to_string())
            }
            // An unknown key in a known section.
            3 => {
                let section = key.rsplit_once('.').map_or("", |(s, _)| s);
                let bogus = if section.is_empty() { "bogus_key".to_string() } else { format!("{section}.bogus_key") };
                if set(&mut table, &bogus, value("1.0")) { Expect::RefusedAt(bogus) } else { Expect::NoPanic }
            }
            // An odd value, or a key removed, or several mutations at once.
            4 => {
                set(&mut table, &key, value(rng.pick::<&str>(&ODD)));
                Expect::NoPanic
            }
            _ => {
                remove(&mut table, &key);
                for _ in 0..rng.below(3) {
                    let k = rng.pick(&KEYS);
                    set(&mut table, k, value(rng.pick::<&str>(&ODD)));
                }
                Expect::NoPanic
            }
        };
        let what = format!("scenario mutant {i} (kind {kind}, key {key}, on {})", file.display());
        let result = bounded(&what, move || load_table(table, file));
        total += 1;
        match (expect, result) {
            (Expect::RefusedAt(k), Err(ScenarioError::Invalid { key, .. })) => {
                assert_eq!(key, k, "{what}: the wrong key named");
                refused += 1;
            }
            (Expect::RefusedAt(_), other) => panic!("{what}: accepted or not refused on its key: {other:?}"),
            (Expect::NoPanic, r) => refused += usize::from(r.is_err()),
        }
    }
    eprintln!("{total} scenario mutants, {refused} refused, {:.2} s", started.elapsed().as_secs_f64());
    assert!(refused > total / 2, "the harness must mostly produce nonsense");
}

#[test]
fn set_arguments_and_raw_text_mutants_never_panic() {
    let mut rng = Rng(0xC0FF_EE18);
    let file = root().join("scenarios/crimper.toml");
    let text = std::fs::read(&file).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for i in 0..120 {
        if i % 2 == 0 {
            // `--set KEY=VALUE` as typed on the command line: nonsense must be refused.
            let key = *rng.pick(&KEYS);
            let raw = if key == "seed" { "1e300" } else { *rng.pick(&NONSENSE) };
            let arg = format!("{key}={raw}");
            let what = format!("--set {arg}");
            let f = file.clone();
            let r = bounded(&what, move || {
                let o: Result<tendril_config::Override, _> = arg.parse();
                o.and_then(|o| tendril_config::load::<PickPlaceScenario>(&f, &[o]).map(|_| ()))
            });
            assert!(r.is_err(), "{what}: accepted");
        } else {
            // The file's bytes cut, or with random bytes spliced in (invalid UTF-8 included).
            let mut bytes = text.clone();
            let at = rng.below(bytes.len());
            if rng.below(2) == 0 {
                bytes.truncate(at);
            } else {
                for _ in 0..1 + rng.below(4) {
                    bytes.insert(at, (rng.next() & 0xFF) as u8);
                }
            }
            let path = dir.path().join(format!("mutant-{i}.toml"));
            std::fs::write(&path, &bytes).unwrap();
            let what = format!("text mutant {i}");
            let _ = bounded(&what, move || tendril_config::load::<PickPlaceScenario>(&path, &[]).map(|_| ()));
        }
    }
}

#[test]
fn sweep_mutants_are_refused_naming_the_sweep_file_and_never_hang() {
    let mut rng = Rng(0x5A5A_0018);
    let dir = tempfile::tempdir().unwrap();
    let scenario = root().join("scenarios/short-lift.toml");
    for i in 0..60 {
        let sweep = dir.path().join(format!("sweep-{i}.toml"));
        let key = *rng.pick(&KEYS);
        let kind = rng.below(4);
        let (body, must_refuse) = match kind {
            // One nonsensical value among valid ones in a grid.
            0 => {
                let bad = if key == "seed" { "1e300" } else { *rng.pick(&NONSENSE) };
                (format!("[grid]\n'{key}' = [{bad}]\n"), true)
            }
            // A grid far beyond the run limit: refused before it is expanded.
            1 => {
                let values = (0..200).map(|v| v.to_string()).collect::<Vec<_>>().join(", ");
                let keys = ["a", "b", "c", "d", "e"];
                let grid: String = keys.iter().map(|k| format!("'{k}' = [{values}]\n")).collect();
                (format!("[grid]\n{grid}"), true)
            }
            // A list entry with a nonsensical value.
            2 => {
                let bad = if key == "seed" { "1e300" } else { *rng.pick(&NONSENSE) };
                (format!("[[list]]\nfeedback = true\n[[list]]\n'{key}' = {bad}\n"), true)
            }
            // Odd shapes: an empty range, a value that is not a list, odd values.
            _ => {
                let odd = *rng.pick(&ODD);
                let shape =
                    ["[grid]\n'{k}' = []\n", "[grid]\n'{k}' = {v}\n", "[grid]\n'{k}' = [{v}]\n", "grid = {v}\n"]
                        [rng.below(4)]
                    .replace("{k}", key)
                    .replace("{v}", odd);
                (shape, false)
            }
        };
        std::fs::write(&sweep, format!("scenarios = ['{}']\n{body}", scenario.display())).unwrap();
        let what = format!("sweep mutant {i} (kind {kind}): {body}");
        let path = sweep.clone();
        let r = bounded(&what, move || {
            let s = tendril::sweep::load_sweep(&path)?;
            tendril::sweep::execute::check_runs(&s)
        });
        if must_refuse {
            let err = r.expect_err(&what).to_string();
            assert!(err.contains(&format!("sweep-{i}.toml")), "{what}: names another file: {err}");
        }
    }
}

/// A small but real bench record: the force calibration's bench with one short cycle.
fn base_csv() -> String {
    let file = root().join("scenarios/bench-force-calibration.toml");
    let o: Vec<tendril_config::Override> = [
        "force_cycles.cycles=2",
        "force_cycles.load_time_s=1.0",
        "force_cycles.unload_time_s=1.0",
        "recorder.rate_hz=50.0",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect();
    let s: tendril_fbg::bench::BenchScenario = tendril_config::load(&file, &o).unwrap();
    tendril_fbg::bench::run(&s).to_csv()
}

#[test]
fn bench_csv_mutants_are_refused_naming_the_line_and_never_spin() {
    let mut rng = Rng(0xCA1B_0018);
    let dir = tempfile::tempdir().unwrap();
    let base = base_csv();
    let good = dir.path().join("good.csv");
    std::fs::write(&good, &base).unwrap();
    assert!(tendril_fbg::calibration::report::calibrate_file(&good).is_ok(), "the base record calibrates");
    let lines: Vec<&str> = base.lines().collect();
    for i in 0..120 {
        let mut rows: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        let line = 1 + rng.below(rows.len() - 1);
        let kind = rng.below(5);
        let must_refuse = match kind {
            // A nonsensical number in a numeric cell of a data row.
            0 | 1 => {
                let mut cells: Vec<String> = rows[line].split(',').map(String::from).collect();
                let col = [0, 1, 2, 3][rng.below(4)];
                cells[col] = ["nan", "inf", "1e160", "1e300", "-1e300", "abc", "1e9"][rng.below(7)].into();
                rows[line] = cells.join(",");
                true
            }
            // A required cell emptied, or a load-cell reading lost.
            2 => {
                let mut cells: Vec<String> = rows[line].split(',').map(String::from).collect();
                cells[[0, 1, 2, 3][rng.below(4)]] = String::new();
                rows[line] = cells.join(",");
                true
            }
            // Time frozen at zero on every row.
            3 => {
                for r in rows.iter_mut().skip(1) {
                    *r = format!("0{}", &r[r.find(',').unwrap()..]);
                }
                true
            }
            // Cut mid-line, or a row with a cell missing: anything but a panic or a hang.
            _ => {
                rows.truncate(line + 1);
                let last = rows.last_mut().unwrap();
                last.truncate(rng.below(last.len() + 1));
                false
            }
        };
        let path = dir.path().join(format!("bench-{i}.csv"));
        std::fs::write(&path, rows.join("\n") + "\n").unwrap();
        let what = format!("CSV mutant {i} (kind {kind}, line {})", line + 1);
        let p = path.clone();
        let r = bounded(&what, move || tendril_fbg::calibration::report::calibrate_file(&p).map_err(|e| e.to_string()));
        if must_refuse {
            let err = r.expect_err(&what);
            assert!(err.contains(&format!("bench-{i}.csv")), "{what}: {err}");
        }
    }
}

/// A handful through the binary, each bounded: nonsense exits non-zero, fast, without a panic.
#[test]
fn a_handful_of_mutants_through_the_binary() {
    let dir = tempfile::tempdir().unwrap();
    // A load-cell reading of 1e160 on the third data row (it once made the fit spin for ever).
    let mut lines: Vec<String> = base_csv().lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[3].split(',').map(String::from).collect();
    cells[1] = "1e160".into();
    lines[3] = cells.join(",");
    let csv = dir.path().join("huge.csv");
    std::fs::write(&csv, lines.join("\n") + "\n").unwrap();
    let crimper = root().join("scenarios/crimper.toml").display().to_string();
    let sweep = dir.path().join("sweep.toml");
    std::fs::write(
        &sweep,
        format!(
            "scenarios = ['{}']\n[grid]\n'task.grasp_s' = [3.0, 1e9]\n",
            root().join("scenarios/short-lift.toml").display()
        ),
    )
    .unwrap();
    let runs: Vec<Vec<String>> = vec![
        vec!["run".into(), crimper.clone(), "--set".into(), "task.grasp_s=1e9".into()],
        vec!["run".into(), crimper.clone(), "--set".into(), "interrogator.sample_rate_hz=nan".into()],
        vec!["run".into(), crimper.clone(), "--set".into(), "object.position_m=[1e9,1e9]".into()],
        vec!["calibrate".into(), csv.display().to_string()],
        vec!["sweep".into(), sweep.display().to_string(), "--out".into(), dir.path().join("o").display().to_string()],
    ];
    for args in runs {
        let started = Instant::now();
        let mut child = tendril_command()
            .args(&args)
            .current_dir(dir.path())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            if started.elapsed() > Duration::from_secs(20) {
                let _ = child.kill();
                panic!("{args:?}: still running after 20 s");
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let out = child.wait_with_output().unwrap();
        let err = stderr(&out);
        assert!(!status.success(), "{args:?} accepted");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(err.contains("tendril:"), "{args:?}: no message: {err}");
    }
}
