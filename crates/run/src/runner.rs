//! A whole run on any [`Cell`] at once, through one [`Session`]: what the command line, sweeps
//! and studies do with the task. The types a run is made of and leaves are re-exported here.

pub use super::plan::ControlPlan;
pub use super::report::{Drop, MAX_CONSECUTIVE_INVALID_SAMPLES, Outcome, RunReport};
use super::session::Session;
use tendril_cell::Cell;
use tendril_control::controller::ForceController;

/// Runs the task on `cell` to its end with the controller `plan.controller` describes. The cell
/// is configured, activated and, whatever happens, deactivated. Cell errors end the run with
/// [`Outcome::Error`]; the rows up to the error are kept. (A [`Session`] steps a run one tick at
/// a time, and writes a trace.)
pub fn run_task(cell: &mut dyn Cell, plan: &ControlPlan) -> RunReport {
    run_task_with_controller(cell, plan, plan.controller.build())
}

/// As [`run_task`], with the force controller given (`plan.controller` is not used): any
/// [`ForceController`], including one defined outside the crate.
pub fn run_task_with_controller(
    cell: &mut dyn Cell,
    plan: &ControlPlan,
    controller: Box<dyn ForceController>,
) -> RunReport {
    let mut session = Session::start(cell, plan, controller, None);
    session.run_to_end();
    session.finish().0
}
