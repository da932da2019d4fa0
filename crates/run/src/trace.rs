//! `trace.csv`: one row per control tick, streamed to disk as the run goes.

use std::io::Write;
use std::path::Path;
use tendril_control::task::Phase;
use tendril_fbg::array::PerPad;

/// One further pad of a sensor array at one tick (pad 0's are the row's own columns).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PadRow {
    /// True normal force on the pad \[N\] (NaN without ground truth).
    pub true_force_n: f64,
    /// Its strain grating's peak \[nm\].
    pub fbg1_nm: f64,
    /// Its reference grating's peak \[nm\] (pad 0's when it shares that one).
    pub fbg2_nm: f64,
    /// Its force estimate, eq. (8) \[N\].
    pub force_n: f64,
}

/// A sensor array's columns of one tick: each further pad's, and the force the controller
/// regulated over all pads (`array.control`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ArrayRow {
    /// The further pads (empty without an array: the trace then has no array columns).
    pub pads: PerPad<PadRow>,
    /// The force the controller regulated \[N\]: pad 0's estimate, the pads' total or their largest.
    pub control_force_n: f64,
}

/// A produce item's columns of one tick (what only a simulation knows).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ProduceRow {
    /// The largest peak contact pressure on the item at the tick's last physics step \[kPa\].
    pub pressure_kpa: f64,
    /// The area above its bruise threshold then \[mm²\].
    pub bruise_area_mm2: f64,
    /// The stem's tension \[N\] (0 without a stem, or once it let go).
    pub stem_tension_n: f64,
    /// Whether the item still hangs from its plant.
    pub on_plant: bool,
    /// Normal force on the pad's bump alone \[N\] (`true_force_n` is the bump's and the casing's).
    pub bump_force_n: f64,
}

/// The columns a produce item adds after all others (none for a rigid object): the contact
/// pressure, the area above the bruise threshold, the stem's tension, whether the item still
/// hangs from its plant, and the pad's bump's share of its force (the bump's force alone).
pub const PRODUCE_COLUMNS: [&str; 5] =
    ["pressure_kpa", "bruise_area_mm2", "stem_tension_n", "on_plant", "bump_force_n"];

/// One control tick, as written to `trace.csv`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceRow {
    /// Cell time \[s\].
    pub time_s: f64,
    /// Task phase.
    pub phase: Phase,
    /// True normal force on the sensor \[N\] (NaN when the cell has no ground truth).
    pub true_force_n: f64,
    /// FBG1 peak \[nm\].
    pub fbg1_nm: f64,
    /// FBG2 peak \[nm\].
    pub fbg2_nm: f64,
    /// Temperature-compensated force estimate, eq. (8) \[N\].
    pub force_n: f64,
    /// Estimate without temperature compensation \[N\].
    pub force_uncompensated_n: f64,
    /// Whether the estimate was flagged over range.
    pub over_range: bool,
    /// Force setpoint \[N\].
    pub setpoint_n: f64,
    /// Whether the force controller ran.
    pub controller_on: bool,
    /// Controller output: twine motor speed [°/s].
    pub controller_output_deg_s: f64,
    /// Growth motor position \[rad\].
    pub growth_motor_rad: f64,
    /// Twine motor position \[rad\].
    pub twine_motor_rad: f64,
    /// Object height above the table \[m\] (NaN without ground truth).
    pub object_height_m: f64,
    /// Object speed relative to the hand [m/s] (NaN without ground truth).
    pub slip_speed_m_s: f64,
    /// Total grip normal force \[N\] (NaN without ground truth).
    pub grip_force_n: f64,
    /// The tool's load as the wrist force sensor reads it \[N\] (NaN without one).
    pub tool_load_n: f64,
    /// A sensor array's further pads (empty without one).
    pub array: ArrayRow,
    /// A produce item's pressure and stem (`None` for a rigid object, or without ground truth).
    pub produce: Option<ProduceRow>,
}

impl TraceRow {
    /// The force the controller regulated \[N\]: pad 0's estimate (`force_n`), or with a sensor
    /// array the signal `array.control` names. What the run's metrics judge.
    pub fn controlled_n(&self) -> f64 {
        if self.array.pads.is_empty() { self.force_n } else { self.array.control_force_n }
    }
}

impl TraceRow {
    /// A tick at `time_s` in `phase` whose true force and estimates are `force_n`, everything else
    /// zero (the setpoint 0.6 N, the controller on): the rows tests compare traces with.
    pub fn at(time_s: f64, phase: Phase, force_n: f64) -> TraceRow {
        TraceRow {
            time_s,
            phase,
            true_force_n: force_n,
            fbg1_nm: 0.0,
            fbg2_nm: 0.0,
            force_n,
            force_uncompensated_n: force_n,
            over_range: false,
            setpoint_n: 0.6,
            controller_on: true,
            controller_output_deg_s: 0.0,
            growth_motor_rad: 0.0,
            twine_motor_rad: 0.0,
            object_height_m: 0.0,
            slip_speed_m_s: 0.0,
            grip_force_n: 0.0,
            tool_load_n: 0.0,
            array: ArrayRow::default(),
            produce: None,
        }
    }
}

const HEADER: &str = "time_s,phase,true_force_n,fbg1_nm,fbg2_nm,force_n,force_uncompensated_n,over_range,setpoint_n,\
controller_on,controller_output_deg_s,growth_motor_rad,twine_motor_rad,object_height_m,slip_speed_m_s,grip_force_n,\
tool_load_n";

/// Bytes of whole rows collected before they are written: 8 KiB (about 70 rows, 0.7 s of a run
/// at 100 Hz), what a `BufWriter` holds, so a process killed outright loses as little as before.
const BUFFER_BYTES: usize = 8 * 1024;

/// The columns a sensor array adds after those of every trace, for `further_pads` pads beyond
/// pad 0: each pad's true force, peaks and estimate (`pad{k}_true_force_n`, `pad{k}_fbg1_nm`, `pad{k}_fbg2_nm`,
/// `pad{k}_force_n`, k from 1), then `control_force_n`, the force the controller regulated; none
/// without an array. A row's values are in the same order ([`TraceWriter::write`]).
pub fn array_columns(further_pads: usize) -> Vec<String> {
    let mut names: Vec<String> = (1..=further_pads)
        .flat_map(|k| ["true_force_n", "fbg1_nm", "fbg2_nm", "force_n"].map(|q| format!("pad{k}_{q}")))
        .collect();
    if further_pads > 0 {
        names.push("control_force_n".into());
    }
    names
}

/// Streams rows to a CSV file; rows already written survive a failed run. Rows are collected
/// whole and written in whole rows only; if a write fails (a full disk) the file is cut back to
/// the rows written before, so it always ends between rows. The first write error is kept
/// ([`TraceWriter::error`]) so it can be reported even when the run goes on to fail for it.
pub struct TraceWriter {
    file: std::fs::File,
    buffer: Vec<u8>,
    /// Whether the header is in the buffer or on disk (it goes with the first row, which says
    /// whether the run has array columns).
    header: bool,
    /// Length of the file's whole rows on disk.
    written: u64,
    error: Option<String>,
}

impl TraceWriter {
    /// Creates (truncates) `path`; the header goes out with the first rows.
    pub fn create(path: &Path) -> std::io::Result<TraceWriter> {
        Ok(TraceWriter {
            file: std::fs::File::create(path)?,
            buffer: Vec::new(),
            header: false,
            written: 0,
            error: None,
        })
    }

    /// Writes the collected rows; on failure cuts the file back to the rows written before.
    fn flush_rows(&mut self) -> std::io::Result<()> {
        if self.buffer.is_empty() {
            return Ok(());
        }
        let result = self.file.write_all(&self.buffer);
        match result {
            Ok(()) => {
                self.written += self.buffer.len() as u64;
                self.buffer.clear();
                Ok(())
            }
            Err(e) => {
                use std::io::Seek;
                let _ = self
                    .file
                    .set_len(self.written)
                    .and_then(|()| self.file.seek(std::io::SeekFrom::Start(self.written)));
                self.buffer.clear();
                self.keep(Err(e))
            }
        }
    }

    /// Appends one row.
    pub fn write(&mut self, r: &TraceRow) -> std::io::Result<()> {
        if let Some(e) = &self.error {
            // After a failure no row is written: the trace stays a prefix of the run.
            return Err(std::io::Error::other(e.clone()));
        }
        if !self.header {
            self.header = true;
            self.buffer.extend_from_slice(HEADER.as_bytes());
            for name in array_columns(r.array.pads.len()) {
                write!(self.buffer, ",{name}")?;
            }
            if r.produce.is_some() {
                for name in PRODUCE_COLUMNS {
                    write!(self.buffer, ",{name}")?;
                }
            }
            self.buffer.push(b'\n');
        }
        // Formatted straight into the row buffer: no allocation per control tick.
        write!(
            self.buffer,
            "{:.4},{},{:.5},{:.4},{:.4},{:.5},{:.5},{},{:.3},{},{:.3},{:.5},{:.5},{:.5},{:.5},{:.4},{:.3}",
            r.time_s,
            r.phase.name(),
            r.true_force_n,
            r.fbg1_nm,
            r.fbg2_nm,
            r.force_n,
            r.force_uncompensated_n,
            u8::from(r.over_range),
            r.setpoint_n,
            u8::from(r.controller_on),
            r.controller_output_deg_s,
            r.growth_motor_rad,
            r.twine_motor_rad,
            r.object_height_m,
            r.slip_speed_m_s,
            r.grip_force_n,
            r.tool_load_n,
        )?;
        for p in r.array.pads.as_slice() {
            write!(self.buffer, ",{:.5},{:.4},{:.4},{:.5}", p.true_force_n, p.fbg1_nm, p.fbg2_nm, p.force_n)?;
        }
        if !r.array.pads.is_empty() {
            write!(self.buffer, ",{:.5}", r.array.control_force_n)?;
        }
        if let Some(p) = &r.produce {
            write!(
                self.buffer,
                ",{:.3},{:.4},{:.4},{},{:.5}",
                p.pressure_kpa,
                p.bruise_area_mm2,
                p.stem_tension_n,
                u8::from(p.on_plant),
                p.bump_force_n
            )?;
        }
        self.buffer.push(b'\n');
        if self.buffer.len() >= BUFFER_BYTES { self.flush_rows() } else { Ok(()) }
    }

    /// Writes every collected row and syncs the file to disk.
    pub fn flush(&mut self) -> std::io::Result<()> {
        if !self.header && self.error.is_none() {
            // A run that ended before its first row still leaves a trace with its header.
            self.header = true;
            self.buffer.extend_from_slice(HEADER.as_bytes());
            self.buffer.push(b'\n');
        }
        self.flush_rows()?;
        let synced = self.file.sync_data();
        self.keep(synced)
    }

    /// The first write error, if any.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    fn keep(&mut self, result: std::io::Result<()>) -> std::io::Result<()> {
        if let Err(e) = &result
            && self.error.is_none()
        {
            self.error = Some(e.to_string());
        }
        result
    }
}
