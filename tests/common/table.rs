//! The CSV files the studies write, read as a test reads them.

use std::collections::HashMap;
use std::path::Path;

/// Every row of the CSV file at `path`, each as column name -> cell text.
pub fn read_rows(path: &Path) -> Vec<HashMap<String, String>> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(str::to_string).collect();
    r.records().map(|rec| header.iter().cloned().zip(rec.unwrap().iter().map(str::to_string)).collect()).collect()
}
