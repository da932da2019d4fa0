//! Merging the `results.csv` of a sweep's shards into one.

use super::durable::ResultsError;
use std::path::Path;

/// Merges shard files into `out`: one header, rows sorted by run id, duplicates dropped.
/// Every input is checked as `--resume` checks it ([`super::durable::scan`]): a torn header or last
/// line, a row that is not whole, or rows of another sweep (another `sweep_id`) refuse the merge.
/// The merged file is written beside `out` and renamed over it, so a failed merge leaves no
/// half-written `out`. Returns the number of rows written.
pub fn merge(inputs: &[&Path], out: &Path) -> Result<usize, ResultsError> {
    let mut header: Option<(String, &Path)> = None;
    let mut sweep: Option<(String, &Path)> = None;
    let mut rows: std::collections::BTreeMap<usize, String> = Default::default();
    for input in inputs {
        let bytes = super::durable::read_regular(input)?;
        let scan = super::durable::scan(&bytes, input)?;
        if let Some(torn) = scan.torn_tail {
            return Err(ResultsError::TornLastLine { file: input.to_path_buf(), bytes: torn.len });
        }
        match &header {
            None => header = Some((scan.header.clone(), input)),
            Some((first, first_file)) if *first != scan.header => {
                return Err(ResultsError::HeaderMismatch {
                    file: input.to_path_buf(),
                    first: first_file.to_path_buf(),
                });
            }
            _ => {}
        }
        for r in scan.rows {
            match &sweep {
                None => sweep = Some((r.sweep_id.clone(), input)),
                Some((id, first_file)) if *id != r.sweep_id => {
                    return Err(ResultsError::ForeignSweep {
                        file: input.to_path_buf(),
                        line: r.line,
                        found: r.sweep_id,
                        expected: format!("{id} (the sweep of {})", first_file.display()),
                    });
                }
                _ => {}
            }
            rows.entry(r.run_id).or_insert(r.text);
        }
    }
    let mut text = header.map(|(h, _)| h + "\n").unwrap_or_default();
    for line in rows.values() {
        text += line;
        text.push('\n');
    }
    super::durable::write_atomically(out, text.as_bytes())?;
    Ok(rows.len())
}
