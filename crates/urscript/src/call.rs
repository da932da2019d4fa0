//! What a built-in call gets and gives: the arguments (`Args`), what it may touch ([`Cx`]), what
//! it returns ([`Outcome`]), and what the controller measured each cycle ([`Measured`]).

use super::controller::Controller;
use super::motion::Arm;
use super::setup::Setup;
use super::value::Value;
use std::collections::VecDeque;

/// Control cycles of measurements kept (for `get_actual_joint_positions_history` and
/// `tool_contact`): 2 s.
pub const JOINT_HISTORY_CYCLES: usize = 1000;

/// What the controller measured in one cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Joint angles \[rad\].
    pub q: [f64; 6],
    /// The wrist sensor's wrench on the tool, base frame \[N, N·m\].
    pub force: [f64; 6],
}

/// What a built-in gives back.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Not done yet (a socket read whose bytes have not all arrived): the thread waits a cycle
    /// and makes the same call again ([`Cx::call_started`] then tells when it first ran).
    Block,
    /// A value, at once.
    Value(Value),
    /// A value, after waiting this long \[s\] (`sync`, `sleep`, `servoj`, `speedj`).
    Sleep(Value, f64),
    /// A value, once this motion is over (`movej`, `movel`, `stopj`).
    Move(Value, u64),
}

/// What a built-in may touch.
pub struct Cx<'a> {
    /// The controller around the interpreter.
    pub host: &'a mut dyn Controller,
    /// The motion generator.
    pub arm: &'a mut Arm,
    /// Twin time \[s\].
    pub now: f64,
    /// The calling thread.
    pub thread: u64,
    /// The controller cycle \[s\].
    pub period: f64,
    /// When this call first ran \[s\]: `now`, unless the thread has been waiting in it.
    pub call_started: f64,
    /// The controller settings the program changes.
    pub setup: &'a mut Setup,
    /// What was measured each cycle, newest first.
    pub history: &'a VecDeque<Measured>,
    /// A secondary program: nothing that consumes time or moves the arm.
    pub secondary: bool,
    /// Set when the call used a socket (I/O, not computation: see
    /// [`crate::interp::ENDLESS_FRAMES`]).
    pub socket_io: bool,
}

/// Positional and keyword arguments of one call.
pub(crate) struct Args<'a> {
    pub(crate) name: &'a str,
    pos: &'a [Value],
    kw: &'a [(String, Value)],
}

impl<'a> Args<'a> {
    /// The arguments of a call to `name`.
    pub(crate) fn new(name: &'a str, pos: &'a [Value], kw: &'a [(String, Value)]) -> Args<'a> {
        Args { name, pos, kw }
    }

    /// Checks the call against the parameter list (in order).
    pub(crate) fn check(&self, params: &[&str]) -> Result<(), String> {
        if self.pos.len() > params.len() {
            return Err(format!("{} takes at most {} arguments, {} given", self.name, params.len(), self.pos.len()));
        }
        for (k, _) in self.kw {
            if !params.contains(&k.as_str()) {
                return Err(format!("{} has no parameter `{k}`", self.name));
            }
        }
        Ok(())
    }

    pub(crate) fn get(&self, i: usize, key: &str) -> Option<&Value> {
        self.pos.get(i).or_else(|| self.kw.iter().find(|(k, _)| k == key).map(|(_, v)| v))
    }

    pub(crate) fn value(&self, i: usize, key: &str) -> Result<&Value, String> {
        self.get(i, key).ok_or_else(|| format!("{}: missing argument `{key}`", self.name))
    }

    pub(crate) fn num(&self, i: usize, key: &str) -> Result<f64, String> {
        self.value(i, key)?.num(&format!("{}'s `{key}`", self.name))
    }

    pub(crate) fn num_or(&self, i: usize, key: &str, default: f64) -> Result<f64, String> {
        match self.get(i, key) {
            Some(v) => v.num(&format!("{}'s `{key}`", self.name)),
            None => Ok(default),
        }
    }

    pub(crate) fn six(&self, i: usize, key: &str) -> Result<[f64; 6], String> {
        self.value(i, key)?.six(&format!("{}'s `{key}`", self.name))
    }

    pub(crate) fn index(&self, i: usize, key: &str, count: usize) -> Result<usize, String> {
        let v = self.num(i, key)?;
        if v < 0.0 || v.fract() != 0.0 || v >= count as f64 {
            return Err(format!("{}: index {v} is not in 0..{}", self.name, count - 1));
        }
        Ok(v as usize)
    }

    pub(crate) fn boolean(&self, i: usize, key: &str) -> Result<bool, String> {
        self.value(i, key)?.truthy()
    }
}
