//! `tendril fit` against published figures (`[[targets]]`) instead of recordings: a three-evaluation
//! fit of the short lift writes its overlay (a scoped parameter as a comment) and a report whose
//! objective and target residuals are those of real runs.

use crate::common::cli::{stderr, tendril};

#[test]
fn a_fit_to_targets_writes_its_overlay_and_report() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = std::fs::canonicalize("scenarios/short-lift.toml").unwrap();
    let spec = dir.path().join("fit.toml");
    let text = format!(
        "[[targets]]\nscenario = \"{}\"\nname = \"lift\"\nfeedback = true\noutcome = \"held\"\n\
         rise_time_max_s = 0.01\nrise_time_tol_s = 0.5\n\
         [parameters.\"lift:object.friction\"]\nmin = 0.6\nmax = 1.2\nstart = 0.85\n\
         [parameters.\"finger.relaxation_time_s\"]\nmin = 10.0\nmax = 20.0\nstart = 15.0\n\
         [budget]\nevaluations = 3\npopulation = 2\n",
        scenario.display()
    );
    std::fs::write(&spec, text).unwrap();
    let out = dir.path().join("out");
    let o = tendril(&["fit", spec.to_str().unwrap(), "--out", out.to_str().unwrap(), "--threads", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    // The start, then one generation of two.
    assert_eq!(report["evaluations"], 3);
    let objective = report["objective"].as_f64().unwrap();
    // The short lift holds and rises in about a second: a rise bound of 0.01 s must cost.
    assert!(objective.is_finite() && objective > 0.0 && objective < 100.0, "{report}");
    let targets = report["targets"].as_array().unwrap();
    assert_eq!(targets.len(), 1, "{report}");
    assert_eq!(targets[0]["target"], "lift feedback on seed 1");
    assert_eq!(targets[0]["outcome"], "held");
    let rise = targets[0]["rise_time_90_s"].as_f64().unwrap();
    assert!((targets[0]["score"].as_f64().unwrap() - (rise - 0.01) / 0.5).abs() < 1e-9, "{report}");
    let overlay = std::fs::read_to_string(out.join("overlay.toml")).unwrap();
    assert!(overlay.contains("\"finger.relaxation_time_s\" = "), "{overlay}");
    // The friction holds for the target's runs alone: written for a reader, not applied.
    assert!(overlay.contains("# lift only: \"object.friction\" = "), "{overlay}");
    let run = dir.path().join("run");
    let overlay = out.join("overlay.toml");
    let o = tendril(&[
        "run",
        "scenarios/short-lift.toml",
        "--overlay",
        overlay.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "the overlay does not apply: {}", stderr(&o));
}
