//! `tendril reproduce`: the paper's figures next to the twin's, with a tolerance and a verdict.
//!
//! Each experiment family (sensor bench, gripper pick-and-place) produces [`Row`]s; this module
//! prints them as a table or writes them as JSON, and the CLI exits non-zero unless all pass.

use serde::Serialize;

/// One compared quantity.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Row {
    /// What is compared, with its unit (`sensitivity [pm/N]`).
    pub quantity: String,
    /// The paper's value, as the paper states it.
    pub paper: String,
    /// The twin's value.
    pub twin: String,
    /// The accepted band, in words (`± 3 %`).
    pub tolerance: String,
    /// Whether the twin's value lies within the tolerance.
    pub pass: bool,
}

impl Row {
    /// A row comparing numbers: passes when `|twin − paper| ≤ tol` (both finite).
    pub fn within(quantity: &str, paper: f64, twin: f64, tol: f64, unit: &str, digits: usize) -> Row {
        Row {
            quantity: quantity.to_string(),
            paper: format!("{paper:.digits$} {unit}").trim_end().to_string(),
            twin: format!("{twin:.digits$} {unit}").trim_end().to_string(),
            tolerance: format!("± {tol:.digits$} {unit}").trim_end().to_string(),
            pass: twin.is_finite() && (twin - paper).abs() <= tol,
        }
    }
}

/// Formats rows as an aligned plain-text table with a closing `N passed, N failed` line.
pub fn render_table(rows: &[Row]) -> String {
    let headers = ["quantity", "paper", "twin", "tolerance", "pass"];
    let cells: Vec<[String; 5]> = rows
        .iter()
        .map(|r| {
            let verdict = if r.pass { "pass" } else { "FAIL" };
            [r.quantity.clone(), r.paper.clone(), r.twin.clone(), r.tolerance.clone(), verdict.to_string()]
        })
        .collect();
    let mut widths = headers.map(|h| h.chars().count());
    for row in &cells {
        for (w, c) in widths.iter_mut().zip(row) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cols: [&str; 5]| -> String {
        let padded: Vec<String> =
            cols.iter().zip(widths).map(|(c, w)| format!("{c}{}", " ".repeat(w - c.chars().count()))).collect();
        format!("| {} |\n", padded.join(" | "))
    };
    let mut out = line(headers);
    out += &line(widths.map(|w| "-".repeat(w)).each_ref().map(|s| s.as_str()));
    for row in &cells {
        out += &line(row.each_ref().map(|s| s.as_str()));
    }
    let passed = rows.iter().filter(|r| r.pass).count();
    out += &format!("reproduce: {} passed, {} failed\n", passed, rows.len() - passed);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_passes_inside_and_fails_outside_or_nan() {
        assert!(Row::within("x", 1.0, 1.02, 0.03, "N", 2).pass);
        assert!(!Row::within("x", 1.0, 1.05, 0.03, "N", 2).pass);
        assert!(!Row::within("x", 1.0, f64::NAN, 0.03, "N", 2).pass);
    }

    #[test]
    fn table_counts_passes_and_failures() {
        let rows = [Row::within("a", 1.0, 1.0, 0.1, "", 1), Row::within("b", 1.0, 2.0, 0.1, "", 1)];
        let table = render_table(&rows);
        assert!(table.ends_with("reproduce: 1 passed, 1 failed\n"), "{table}");
        assert!(table.contains("FAIL"));
    }
}
pub mod gripper;
pub mod sensor;
