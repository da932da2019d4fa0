//! Results files that survive any crash (issue 18): every case a torn write, a full disk, a
//! foreign file or a second process can leave, checked through the library without running a
//! simulation (rows are written from a default summary), plus the writers on a full device.

use std::path::{Path, PathBuf};
use tendril::sweep::columns::{header, row, sweep_id};
use tendril::sweep::durable::{ResultsError, ResultsFile, scan};
use tendril::sweep::results::merge;
use tendril::sweep::{Sweep, load_sweep};
use tendril_run::summary::RunSummary;

/// A sweep of 12 runs (seeds 1-12, so ids reach two digits) over crimper.toml, written to `dir`.
fn twelve_runs(dir: &Path, kp: f64) -> Sweep {
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml");
    let file = dir.join(format!("sweep-{kp}.toml"));
    let seeds: Vec<String> = (1..=12).map(|s| s.to_string()).collect();
    std::fs::write(
        &file,
        format!(
            "scenarios = ['{}']\n[grid]\n'controller.kp' = [{kp:?}]\nseed = [{}]\n",
            scenario.display(),
            seeds.join(",")
        ),
    )
    .unwrap();
    load_sweep(&file).unwrap()
}

fn head(sweep: &Sweep) -> Vec<String> {
    header(sweep, &RunSummary::columns())
}

/// The file a sweep writes after finishing runs `ids`, as bytes.
fn results_text(sweep: &Sweep, ids: &[usize]) -> String {
    let id = sweep_id(sweep);
    let mut w = csv::WriterBuilder::new().from_writer(Vec::new());
    w.write_record(head(sweep)).unwrap();
    for &i in ids {
        w.write_record(row(sweep, &id, &sweep.runs[i], &RunSummary::default())).unwrap();
    }
    String::from_utf8(w.into_inner().unwrap()).unwrap()
}

fn resume(path: &Path, sweep: &Sweep) -> Result<(ResultsFile, tendril::sweep::durable::Opened), ResultsError> {
    ResultsFile::open(path, sweep, &sweep_id(sweep), &head(sweep), true, None)
}

fn setup(text: &str) -> (tempfile::TempDir, Sweep, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let sweep = twelve_runs(dir.path(), 20.0);
    let path = dir.path().join("results.csv");
    std::fs::write(&path, text).unwrap();
    (dir, sweep, path)
}

#[test]
fn a_torn_fragment_is_cut_off_and_its_run_is_done_again() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = twelve_runs(dir.path(), 20.0);
    let path = dir.path().join("results.csv");
    let whole = results_text(&sweep, &[0, 1, 2]);
    let next = results_text(&sweep, &[3]);
    let row3 = next.lines().nth(1).unwrap();
    std::fs::write(&path, format!("{whole}{}", &row3[..row3.len() / 2])).unwrap();

    let (mut file, opened) = resume(&path, &sweep).unwrap();
    assert_eq!(opened.done.into_iter().collect::<Vec<_>>(), [0, 1, 2]);
    assert_eq!(opened.dropped_tail, Some(row3.len() / 2));
    assert_eq!(std::fs::read_to_string(&path).unwrap(), whole, "cut back to the whole rows");
    // The run is appended again whole: the file scans clean, every row with the header's cells.
    file.append(&row(&sweep, &sweep_id(&sweep), &sweep.runs[3], &RunSummary::default())).unwrap();
    drop(file);
    let s = scan(&std::fs::read(&path).unwrap(), &path).unwrap();
    assert_eq!(s.rows.iter().map(|r| r.run_id).collect::<Vec<_>>(), [0, 1, 2, 3]);
    assert_eq!(s.torn_tail, None);
}

#[test]
fn a_row_missing_only_its_newline_is_not_done() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = twelve_runs(dir.path(), 20.0);
    let path = dir.path().join("results.csv");
    let text = results_text(&sweep, &[0, 1]);
    std::fs::write(&path, text.trim_end_matches('\n')).unwrap();
    let (_file, opened) = resume(&path, &sweep).unwrap();
    assert_eq!(opened.done.into_iter().collect::<Vec<_>>(), [0], "run 1's row was not whole: run again");
    assert!(std::fs::read_to_string(&path).unwrap().ends_with('\n'));
}

#[test]
fn a_fragment_that_reads_as_a_run_id_is_refused_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = twelve_runs(dir.path(), 20.0);
    let path = dir.path().join("results.csv");
    // "1" left by a torn write, then run 0's row glued to it: run id 10, in range, but run 0's cells.
    let text = results_text(&sweep, &[0]);
    let (head_line, row0) = text.split_once('\n').unwrap();
    std::fs::write(&path, format!("{head_line}\n1{row0}")).unwrap();
    let err = resume(&path, &sweep).err().expect("refused");
    assert!(matches!(err, ResultsError::BadRow { line: 2, .. }), "{err}");
    assert!(err.to_string().contains("run 10"), "{err}");
    // "9" glued onto run 4's row: run 94, not in the sweep.
    std::fs::write(&path, format!("{head_line}\n9{}", results_text(&sweep, &[4]).split_once('\n').unwrap().1)).unwrap();
    let err = resume(&path, &sweep).err().expect("refused");
    assert!(err.to_string().contains("line 2") && err.to_string().contains("not in this sweep"), "{err}");
}

#[test]
fn a_torn_header_is_an_error_not_a_rerun() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = twelve_runs(dir.path(), 20.0);
    let path = dir.path().join("results.csv");
    let text = results_text(&sweep, &[]);
    std::fs::write(&path, &text[..text.len() / 2]).unwrap();
    let err = resume(&path, &sweep).err().expect("refused");
    assert!(matches!(err, ResultsError::TornHeader { .. }), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text[..text.len() / 2], "left as found");
}

#[test]
fn a_results_file_of_another_sweep_is_neither_resumed_nor_merged() {
    let dir = tempfile::tempdir().unwrap();
    let (ours, theirs) = (twelve_runs(dir.path(), 20.0), twelve_runs(dir.path(), 40.0));
    assert_eq!(head(&ours), head(&theirs), "same columns");
    assert_ne!(sweep_id(&ours), sweep_id(&theirs));
    let path = dir.path().join("results.csv");
    std::fs::write(&path, results_text(&theirs, &[0, 1])).unwrap();
    let err = resume(&path, &ours).err().expect("refused");
    assert!(matches!(err, ResultsError::ForeignSweep { line: 2, .. }), "{err}");

    let mine = dir.path().join("mine.csv");
    std::fs::write(&mine, results_text(&ours, &[2, 3])).unwrap();
    let out = dir.path().join("merged.csv");
    let err = merge(&[&mine, &path], &out).expect_err("refused");
    assert!(matches!(err, ResultsError::ForeignSweep { .. }), "{err}");
    assert!(!out.exists(), "no half-merged file");
    // Shards of one sweep merge; a torn shard is refused until resumed.
    let other = dir.path().join("other.csv");
    std::fs::write(&other, results_text(&ours, &[0, 1])).unwrap();
    assert_eq!(merge(&[&mine, &other], &out).unwrap(), 4);
    std::fs::write(&other, results_text(&ours, &[0, 1]) + "5,").unwrap();
    assert!(matches!(merge(&[&mine, &other], &out), Err(ResultsError::TornLastLine { .. })));
}

#[test]
fn two_processes_cannot_resume_one_results_file() {
    let (_dir, sweep, path) = setup("");
    let (first, _) = resume(&path, &sweep).unwrap();
    // A second open file description, as a second process has: the lock refuses it.
    let err = resume(&path, &sweep).err().expect("locked");
    assert!(matches!(err, ResultsError::Locked { .. }), "{err}");
    drop(first);
    assert!(resume(&path, &sweep).is_ok(), "the lock goes with the first");
}

#[test]
fn a_fresh_sweep_refuses_an_existing_file_and_a_device() {
    let (_dir, sweep, path) = setup("x");
    let fresh = ResultsFile::open(&path, &sweep, &sweep_id(&sweep), &head(&sweep), false, None);
    assert!(matches!(fresh, Err(ResultsError::Exists { .. })));
    let dev = Path::new("/dev/zero");
    if dev.exists() {
        let err = ResultsFile::open(dev, &sweep, &sweep_id(&sweep), &head(&sweep), true, None).err().expect("refused");
        assert!(matches!(err, ResultsError::NotResults { .. }), "{err}");
    }
}

#[test]
fn writers_on_a_full_device_report_the_error() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        eprintln!("NOTE: no /dev/full here");
        return;
    }
    // The trace: rows are buffered, so the failure shows at the latest on flush, and is kept.
    let mut trace = tendril_run::trace::TraceWriter::create(full).unwrap();
    let r = tendril_run::trace::TraceRow {
        time_s: 0.0,
        phase: tendril_control::task::Phase::Home,
        true_force_n: 0.0,
        fbg1_nm: 1540.0,
        fbg2_nm: 1550.0,
        force_n: 0.0,
        force_uncompensated_n: 0.0,
        over_range: false,
        setpoint_n: 1.0,
        controller_on: false,
        controller_output_deg_s: 0.0,
        growth_motor_rad: 0.0,
        twine_motor_rad: 0.0,
        object_height_m: 0.0,
        slip_speed_m_s: 0.0,
        grip_force_n: 0.0,
        tool_load_n: f64::NAN,
        array: Default::default(),
        produce: None,
    };
    let wrote = (0..100).all(|_| trace.write(&r).is_ok());
    assert!(!wrote || trace.flush().is_err());
    assert!(trace.error().is_some_and(|e| e.contains("space")), "{:?}", trace.error());
}
