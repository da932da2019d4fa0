//! A run's trace as columns (what `tendril.Run.trace` turns into numpy arrays) and one tick as a
//! dict: the columns of `trace.csv`, in its order, at full precision (the file rounds to 3-5
//! decimals), a sensor array's and a produce item's after them as in the file.

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use tendril_run::trace::{PRODUCE_COLUMNS, TraceRow, array_columns};

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

/// A sensor array's values of a row, in the order of [`array_columns`]: each further pad's true
/// force, peaks and estimate, then the force the controller regulated (none without an array).
fn array_values(r: &TraceRow) -> impl Iterator<Item = f64> + '_ {
    let pads = r.array.pads.as_slice();
    let control = (!pads.is_empty()).then_some(r.array.control_force_n);
    pads.iter().flat_map(|p| [p.true_force_n, p.fbg1_nm, p.fbg2_nm, p.force_n]).chain(control)
}

/// A produce item's values of a row, in the order of [`PRODUCE_COLUMNS`] (none for a rigid
/// object): the pressure, the area above the bruise threshold, the stem's tension, 1 while the
/// item hangs from its plant, and the pad's bump's force alone.
fn produce_values(r: &TraceRow) -> impl Iterator<Item = f64> + '_ {
    r.produce.iter().flat_map(|p| {
        [p.pressure_kpa, p.bruise_area_mm2, p.stem_tension_n, f64::from(u8::from(p.on_plant)), p.bump_force_n]
    })
}

/// Every column of `rows` as `(name, kind, data)`: kind `"f8"` with little-endian float64
/// bytes, `"bool"` with one byte a row, or `"str"` with a list of the phases' names.
pub fn columns<'py>(py: Python<'py>, rows: &[TraceRow]) -> PyResult<Vec<(String, &'static str, Bound<'py, PyAny>)>> {
    let mut out = COLUMNS
        .iter()
        .map(|(name, column)| {
            Ok(match column {
                Column::Float(f) => {
                    let bytes: Vec<u8> = rows.iter().flat_map(|r| f(r).to_le_bytes()).collect();
                    (name.to_string(), "f8", PyBytes::new(py, &bytes).into_any())
                }
                Column::Flag(f) => {
                    let bytes: Vec<u8> = rows.iter().map(|r| u8::from(f(r))).collect();
                    (name.to_string(), "bool", PyBytes::new(py, &bytes).into_any())
                }
                Column::Phase => {
                    let phases: Vec<&str> = rows.iter().map(|r| r.phase.name()).collect();
                    (name.to_string(), "str", phases.into_pyobject(py)?.into_any())
                }
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let names = array_columns(rows.first().map_or(0, |r| r.array.pads.len()));
    let mut data: Vec<Vec<u8>> = vec![Vec::with_capacity(8 * rows.len()); names.len()];
    for r in rows {
        for (bytes, value) in data.iter_mut().zip(array_values(r)) {
            bytes.extend_from_slice(&value.to_le_bytes());
        }
    }
    for (name, bytes) in names.into_iter().zip(data) {
        out.push((name, "f8", PyBytes::new(py, &bytes).into_any()));
    }
    if rows.first().is_some_and(|r| r.produce.is_some()) {
        let mut data: Vec<Vec<u8>> = vec![Vec::with_capacity(8 * rows.len()); PRODUCE_COLUMNS.len()];
        for r in rows {
            for (bytes, value) in data.iter_mut().zip(produce_values(r)) {
                bytes.extend_from_slice(&value.to_le_bytes());
            }
        }
        for (name, bytes) in PRODUCE_COLUMNS.into_iter().zip(data) {
            out.push((name.to_string(), "f8", PyBytes::new(py, &bytes).into_any()));
        }
    }
    Ok(out)
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
    for (name, value) in array_columns(r.array.pads.len()).into_iter().zip(array_values(r)) {
        d.set_item(name, value)?;
    }
    for (name, value) in PRODUCE_COLUMNS.into_iter().zip(produce_values(r)) {
        d.set_item(name, value)?;
    }
    Ok(d)
}
