//! A run's trace as columns (what `tendril.Run.trace` turns into numpy arrays) and one tick as a
//! dict: the columns of `trace.csv`, in its order, at full precision (the file rounds to 3-5
//! decimals).

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use tendril_run::trace::TraceRow;

/// How a column is read from a row.
enum Column {
    /// A number (float64).
    Float(fn(&TraceRow) -> f64),
    /// A flag.
    Flag(fn(&TraceRow) -> bool),
    /// The task phase, by name.
    Phase,
}

/// The columns, in `trace.csv`'s order.
const COLUMNS: [(&str, Column); 17] = [
    ("time_s", Column::Float(|r| r.time_s)),
    ("phase", Column::Phase),
    ("true_force_n", Column::Float(|r| r.true_force_n)),
    ("fbg1_nm", Column::Float(|r| r.fbg1_nm)),
    ("fbg2_nm", Column::Float(|r| r.fbg2_nm)),
    ("force_n", Column::Float(|r| r.force_n)),
    ("force_uncompensated_n", Column::Float(|r| r.force_uncompensated_n)),
    ("over_range", Column::Flag(|r| r.over_range)),
    ("setpoint_n", Column::Float(|r| r.setpoint_n)),
    ("controller_on", Column::Flag(|r| r.controller_on)),
    ("controller_output_deg_s", Column::Float(|r| r.controller_output_deg_s)),
    ("growth_motor_rad", Column::Float(|r| r.growth_motor_rad)),
    ("twine_motor_rad", Column::Float(|r| r.twine_motor_rad)),
    ("object_height_m", Column::Float(|r| r.object_height_m)),
    ("slip_speed_m_s", Column::Float(|r| r.slip_speed_m_s)),
    ("grip_force_n", Column::Float(|r| r.grip_force_n)),
    ("tool_load_n", Column::Float(|r| r.tool_load_n)),
];

/// The column names, in `trace.csv`'s order.
pub fn names() -> Vec<&'static str> {
    COLUMNS.iter().map(|(name, _)| *name).collect()
}

/// Every column of `rows` as `(name, kind, data)`: kind `"f8"` with little-endian float64
/// bytes, `"bool"` with one byte a row, or `"str"` with a list of the phases' names.
pub fn columns<'py>(
    py: Python<'py>,
    rows: &[TraceRow],
) -> PyResult<Vec<(&'static str, &'static str, Bound<'py, PyAny>)>> {
    COLUMNS
        .iter()
        .map(|(name, column)| {
            Ok(match column {
                Column::Float(f) => {
                    let bytes: Vec<u8> = rows.iter().flat_map(|r| f(r).to_le_bytes()).collect();
                    (*name, "f8", PyBytes::new(py, &bytes).into_any())
                }
                Column::Flag(f) => {
                    let bytes: Vec<u8> = rows.iter().map(|r| u8::from(f(r))).collect();
                    (*name, "bool", PyBytes::new(py, &bytes).into_any())
                }
                Column::Phase => {
                    let phases: Vec<&str> = rows.iter().map(|r| r.phase.name()).collect();
                    (*name, "str", phases.into_pyobject(py)?.into_any())
                }
            })
        })
        .collect()
}

/// One row as a dict of the same columns.
pub fn row_dict<'py>(py: Python<'py>, r: &TraceRow) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, column) in &COLUMNS {
        match column {
            Column::Float(f) => d.set_item(name, f(r))?,
            Column::Flag(f) => d.set_item(name, f(r))?,
            Column::Phase => d.set_item(name, r.phase.name())?,
        }
    }
    Ok(d)
}
