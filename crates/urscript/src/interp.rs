//! The interpreter: runs a compiled program's threads in the controller's 2 ms cycle, in twin time.
//!
//! Scheduling follows the URScript manual's "Thread scheduling": each 2 ms frame every thread
//! that can run does, in the order the threads were started (the program's own body first),
//! until it consumes physical time (`sync()`, `sleep`, a motion, a socket read still waiting, a
//! `join`), ends, or uses up its time slice of [`THREAD_SLICE_OPS`] instructions; it then waits
//! for the next frame (it resumes where it was). A thread that uses up its slice for
//! [`ENDLESS_FRAMES`] frames running without consuming time or using a socket is an endless
//! loop: a runtime error (on a controller such a thread starves the control box, which raises
//! "Lost communication with Controller" and a protective stop; here it would only cost the twin
//! its real time). A thread fed by a socket faster than it reads (UR's client library's examples
//! send keepalives as fast as they can) is not one: it works through its slice each frame and the
//! sender is held back by TCP. `enter_critical`/`exit_critical` change nothing: a thread is never
//! interrupted except where it consumes time or at the end of its slice.
//!
//! Errors stop the program with the line and the reason, as a controller's runtime error does.
//! Nothing here does I/O: the arm's state, the RTDE registers and the sockets come through
//! [`Controller`].

use super::ast::Scope;
use super::builtins;
use super::call::{Cx, Outcome};
pub use super::call::{JOINT_HISTORY_CYCLES, Measured};
use super::compile::{Compiled, Function, Op};
use super::controller::Controller;
use super::error::ScriptError;
use super::motion::Arm;
use super::setup::Setup;
use super::value::Value;
use std::collections::{HashMap, VecDeque};
use std::sync::Arc;

/// The controller cycle \[s\]: 500 Hz on e-Series.
pub const CONTROL_PERIOD_S: f64 = 0.002;
/// Instructions one thread may execute in a frame before it waits for the next (its time slice).
/// UR states the slice as the frame's 2 ms of the controller's time, not as a count; 10 000 of our
/// instructions took 0.47-0.73 ms on this project's 2-core machine with both cores loaded by
/// other builds (`cargo test -p tendril-urscript --release time_slice -- --ignored
/// --nocapture`), so a thread using its whole slice leaves the twin most of its 2 ms frame, and
/// UR's external control program (some 200 instructions per message it reads) works through 50
/// messages a frame.
pub const THREAD_SLICE_OPS: usize = 10_000;
/// Consecutive frames a thread may use up its slice without consuming time or using a socket
/// before it is taken for an endless loop: 1 s.
pub const ENDLESS_FRAMES: u32 = 500;
/// Deepest call stack of a thread.
pub const MAX_CALL_DEPTH: usize = 100;
/// Most threads alive at once (the program's body included). UR does not publish its controller's
/// limit; 32 is eight times what the largest programs we run start (UR's external control
/// script runs four threads at once), and keeps a program that starts threads in a loop from
/// growing without bound: the 33rd `run` is a runtime error naming the limit.
pub const MAX_THREADS: usize = 32;

pub use super::motion::KILL_DECEL_RAD_S2;

/// Whether the program runs.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Running.
    Running,
    /// The program's body ended or `halt` ran.
    Finished,
    /// A runtime error stopped it.
    Failed(ScriptError),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Wait {
    Ready,
    Until(f64),
    Motion(u64),
    Join(u64),
}

#[derive(Debug, Clone)]
struct Frame {
    func: Arc<Function>,
    pc: usize,
    locals: HashMap<String, Value>,
    /// The program's own body: its variables are the globals.
    program_body: bool,
}

#[derive(Debug, Clone)]
struct Thread {
    id: u64,
    frames: Vec<Frame>,
    stack: Vec<Value>,
    wait: Wait,
    ended: bool,
    /// When the call the thread is blocked in (a socket read, `socket_open`) first ran \[s\].
    blocked_since: Option<f64>,
    /// Consecutive frames it used up its slice without consuming time or reading a socket.
    busy_frames: u32,
    /// It used a socket this frame.
    socket_io: bool,
    /// The line of the instruction it ran last.
    last_line: u32,
}

impl Thread {
    fn new(id: u64, func: Arc<Function>, program_body: bool) -> Thread {
        Thread {
            id,
            frames: vec![Frame { func, pc: 0, locals: HashMap::new(), program_body }],
            stack: Vec::new(),
            wait: Wait::Ready,
            ended: false,
            blocked_since: None,
            busy_frames: 0,
            socket_io: false,
            last_line: 0,
        }
    }
}

/// A running program.
#[derive(Debug, Clone)]
pub struct Interpreter {
    code: Compiled,
    globals: HashMap<String, Value>,
    threads: Vec<Thread>,
    next_thread: u64,
    arm: Arm,
    status: Status,
    setup: Setup,
    /// What was measured each cycle, newest first.
    history: VecDeque<Measured>,
    /// A secondary program (`sec`): it may not consume time or move the arm.
    secondary: bool,
    /// The program's name (its `def`'s or `sec`'s).
    name: String,
}

impl Interpreter {
    /// Parses and compiles `text` (a `def` or a `sec` program); the arm starts at rest at `q`
    /// \[rad\].
    pub fn new(text: &str, q: [f64; 6]) -> Result<Interpreter, ScriptError> {
        let program = super::parser::parse_program(text)?;
        let (secondary, name) = (program.secondary, program.name.clone());
        let code = super::compile::compile(&program)?;
        let main = Thread::new(0, code.main.clone(), true);
        Ok(Interpreter {
            code,
            globals: HashMap::new(),
            threads: vec![main],
            next_thread: 1,
            arm: Arm::new(q),
            status: Status::Running,
            setup: Setup::default(),
            history: VecDeque::new(),
            secondary,
            name,
        })
    }

    /// The program's name (`prog` for `def prog():`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Whether this is a secondary program (`sec name():`), which runs beside the main one.
    pub fn is_secondary(&self) -> bool {
        self.secondary
    }

    /// The controller settings the program made ([`Setup`]).
    pub fn setup(&self) -> &Setup {
        &self.setup
    }

    /// Replaces the controller settings (another program, a secondary one, changed them).
    pub fn set_setup(&mut self, setup: Setup) {
        self.arm.set_tcp(&setup.tcp);
        self.setup = setup;
    }

    /// Running, finished or failed.
    pub fn status(&self) -> &Status {
        &self.status
    }

    /// The commanded joint angles \[rad\].
    pub fn target_q(&self) -> [f64; 6] {
        self.arm.target_q()
    }

    /// The commanded joint speeds \[rad/s\].
    pub fn target_qd(&self) -> [f64; 6] {
        self.arm.target_qd()
    }

    /// Whether the arm follows `servoj` targets rather than a generated trajectory.
    pub fn servoing(&self) -> bool {
        self.arm.servoing()
    }

    /// A global variable's value (for tests and diagnostics).
    pub fn global(&self, name: &str) -> Option<&Value> {
        self.globals.get(name)
    }

    /// Runs one controller cycle at twin time `now` \[s\]; returns the joint setpoint to command
    /// this cycle, if there is a new one. A runtime error is logged through `host` and ends the
    /// program ([`Interpreter::status`]).
    pub fn step(&mut self, now: f64, host: &mut dyn Controller) -> Option<[f64; 6]> {
        if self.status != Status::Running {
            return None;
        }
        match self.cycle(now, host) {
            Ok(command) => command,
            Err(e) => {
                host.message(&format!("runtime error: {e}"));
                self.status = Status::Failed(e);
                None
            }
        }
    }

    fn cycle(&mut self, now: f64, host: &mut dyn Controller) -> Result<Option<[f64; 6]>, ScriptError> {
        if self.history.len() >= JOINT_HISTORY_CYCLES {
            self.history.pop_back();
        }
        self.history.push_front(Measured { q: host.actual_q(), force: host.actual_tcp_force() });
        let mut i = 0;
        while i < self.threads.len() {
            if !self.threads[i].ended && self.ready(self.threads[i].wait, now) {
                self.threads[i].wait = Wait::Ready;
                let mut thread = std::mem::replace(&mut self.threads[i], placeholder());
                let result = self.run_slice(&mut thread, now, host);
                self.threads[i] = thread;
                result?;
                if self.status != Status::Running {
                    return Ok(None);
                }
            }
            i += 1;
        }
        if self.threads[0].ended {
            self.status = Status::Finished;
            return Ok(None);
        }
        self.threads.retain(|t| !t.ended);
        self.arm.tick(now, CONTROL_PERIOD_S).map_err(|message| ScriptError { line: 0, message })
    }

    fn ready(&self, wait: Wait, now: f64) -> bool {
        match wait {
            Wait::Ready => true,
            Wait::Until(t) => now >= t - 1e-9,
            Wait::Motion(id) => self.arm.finished(id),
            Wait::Join(id) => !self.threads.iter().any(|t| t.id == id && !t.ended),
        }
    }

    /// Runs a thread for one frame: until it consumes time, ends, or uses up its slice.
    fn run_slice(&mut self, th: &mut Thread, now: f64, host: &mut dyn Controller) -> Result<(), ScriptError> {
        th.socket_io = false;
        let mut budget = THREAD_SLICE_OPS;
        self.run(th, now, host, &mut budget)?;
        if budget > 0 || th.socket_io {
            th.busy_frames = 0;
            return Ok(());
        }
        // Its slice is used up: it goes on next frame.
        th.wait = Wait::Until(now + CONTROL_PERIOD_S);
        th.busy_frames += 1;
        if th.busy_frames >= ENDLESS_FRAMES {
            return Err(ScriptError {
                line: th.last_line,
                message: format!(
                    "a thread used its whole {} ms time slice for {} s running without sync(), sleep, a motion or \
                     a socket (an endless loop?)",
                    CONTROL_PERIOD_S * 1e3,
                    f64::from(ENDLESS_FRAMES) * CONTROL_PERIOD_S
                ),
            });
        }
        Ok(())
    }

    fn run(
        &mut self,
        th: &mut Thread,
        now: f64,
        host: &mut dyn Controller,
        budget: &mut usize,
    ) -> Result<(), ScriptError> {
        loop {
            if *budget == 0 {
                return Ok(());
            }
            let Some(frame) = th.frames.last_mut() else {
                th.ended = true;
                return Ok(());
            };
            // The function is shared (an `Arc`): its instructions are read in place, not copied.
            let func = Arc::clone(&frame.func);
            let Some(op) = func.code.get(frame.pc) else {
                th.ended = true;
                return Ok(());
            };
            let line = func.lines[frame.pc];
            th.last_line = line;
            frame.pc += 1;
            let err = |message: String| ScriptError { line, message };
            *budget -= 1;
            match op {
                Op::Const(v) => th.stack.push(v.clone()),
                Op::Load(name) => {
                    let frame = th.frames.last().expect("checked above");
                    let v = frame
                        .locals
                        .get(name)
                        .or_else(|| self.globals.get(name))
                        .cloned()
                        .ok_or_else(|| err(format!("variable `{name}` is not defined")))?;
                    th.stack.push(v);
                }
                Op::Store(name, scope) => {
                    let v = pop(th, line)?;
                    *self.slot(th, name, *scope, true).map_err(err)? = v;
                }
                Op::StoreIndexed(name, n, scope) => {
                    let (n, scope) = (*n, *scope);
                    let v = pop(th, line)?;
                    let at = th.stack.len().checked_sub(n).ok_or_else(|| err("stack underflow".into()))?;
                    let indices = th.stack.split_off(at);
                    let mut target = self.slot(th, name, scope, false).map_err(err)?;
                    for i in &indices[..n - 1] {
                        target = match target {
                            Value::List(l) => {
                                let k = i.num("an index").map_err(&err)?;
                                let len = l.len();
                                l.get_mut(k as usize)
                                    .filter(|_| k >= 0.0 && k.fract() == 0.0)
                                    .ok_or_else(|| err(format!("index {k} out of range (length {len})")))?
                            }
                            other => return Err(err(format!("cannot index {}", other.describe()))),
                        };
                    }
                    target.set_index(&indices[n - 1], v).map_err(err)?;
                }
                Op::Index => {
                    let i = pop(th, line)?;
                    let a = pop(th, line)?;
                    th.stack.push(a.index(&i).map_err(err)?);
                }
                Op::List(n) | Op::Pose(n) => {
                    let n = *n;
                    let at = th.stack.len().checked_sub(n).ok_or_else(|| err("stack underflow".into()))?;
                    let items = th.stack.split_off(at);
                    th.stack.push(if matches!(op, Op::List(_)) {
                        Value::List(items)
                    } else {
                        if n != 6 {
                            return Err(err(format!("a pose has 6 elements, not {n}")));
                        }
                        let v = items.iter().map(|v| v.num("a pose element")).collect::<Result<Vec<_>, _>>();
                        let v = v.map_err(err)?;
                        Value::Pose(std::array::from_fn(|k| v[k]))
                    });
                }
                Op::Neg => {
                    let a = pop(th, line)?;
                    th.stack.push(a.neg().map_err(err)?);
                }
                Op::Not => {
                    let a = pop(th, line)?;
                    th.stack.push(Value::Bool(!a.truthy().map_err(err)?));
                }
                Op::Bin(o) => {
                    let b = pop(th, line)?;
                    let a = pop(th, line)?;
                    th.stack.push(a.binary(*o, &b).map_err(err)?);
                }
                Op::Jump(to) => set_pc(th, *to),
                Op::JumpIfFalse(to) => {
                    if !pop(th, line)?.truthy().map_err(err)? {
                        set_pc(th, *to);
                    }
                }
                Op::AndJump(to) | Op::OrJump(to) => {
                    let top = th.stack.last().ok_or_else(|| err("stack underflow".into()))?;
                    let t = top.truthy().map_err(err)?;
                    if t == matches!(op, Op::OrJump(_)) {
                        set_pc(th, *to);
                    } else {
                        th.stack.pop();
                    }
                }
                Op::Call(name, argc, kw) => {
                    let argc = *argc;
                    let at =
                        th.stack.len().checked_sub(argc + kw.len()).ok_or_else(|| err("stack underflow".into()))?;
                    let mut args = th.stack.split_off(at);
                    let kwargs: Vec<(String, Value)> = kw.iter().cloned().zip(args.split_off(argc)).collect();
                    if let Some(f) = self.code.functions.get(name).cloned() {
                        if f.is_thread {
                            return Err(err(format!("thread `{name}` must be started with `run`")));
                        }
                        if th.frames.len() >= MAX_CALL_DEPTH {
                            return Err(err(format!("calls nested deeper than {MAX_CALL_DEPTH} (recursion?)")));
                        }
                        let locals = bind(&f, args, kwargs).map_err(err)?;
                        th.frames.push(Frame { func: f, pc: 0, locals, program_body: false });
                        continue;
                    }
                    let mut cx = Cx {
                        host: &mut *host,
                        arm: &mut self.arm,
                        now,
                        thread: th.id,
                        period: CONTROL_PERIOD_S,
                        call_started: th.blocked_since.unwrap_or(now),
                        setup: &mut self.setup,
                        history: &self.history,
                        secondary: self.secondary,
                        socket_io: false,
                    };
                    let outcome = builtins::call(name, &args, &kwargs, &mut cx).map_err(err)?;
                    th.socket_io |= cx.socket_io;
                    th.blocked_since = None;
                    match outcome {
                        Outcome::Block => {
                            // Not done yet (a socket read waiting for bytes): the thread parks and
                            // makes the same call again next cycle; the others run meanwhile.
                            th.blocked_since = Some(cx.call_started);
                            th.stack.extend(args);
                            th.stack.extend(kwargs.into_iter().map(|(_, v)| v));
                            if let Some(frame) = th.frames.last_mut() {
                                frame.pc -= 1;
                            }
                            th.wait = Wait::Until(now + CONTROL_PERIOD_S);
                        }
                        Outcome::Value(v) => th.stack.push(v),
                        Outcome::Sleep(v, t) => {
                            th.stack.push(v);
                            th.wait = Wait::Until(now + t.max(CONTROL_PERIOD_S));
                        }
                        Outcome::Move(v, id) => {
                            th.stack.push(v);
                            th.wait = Wait::Motion(id);
                        }
                    }
                }
                Op::Run(name) => {
                    let f = self
                        .code
                        .functions
                        .get(name)
                        .filter(|f| f.is_thread)
                        .cloned()
                        .ok_or_else(|| err(format!("`{name}` is not a thread")))?;
                    if self.threads.iter().filter(|t| !t.ended).count() >= MAX_THREADS {
                        return Err(err(format!("more than {MAX_THREADS} threads")));
                    }
                    let id = self.next_thread;
                    self.next_thread += 1;
                    self.threads.push(Thread::new(id, f, false));
                    th.stack.push(Value::Thread(id));
                }
                Op::Kill | Op::Join => {
                    let id = match pop(th, line)? {
                        Value::Thread(id) => id,
                        // `kill` or `join` of a handle variable still holding its initial 0 does
                        // nothing: SDU ur_rtde's servo_stop kills `servoc_thrd`, 0 unless servoC
                        // ran; UR's external control script joins `thread_move` and
                        // `thread_clear` before it ever started them.
                        _ if matches!(op, Op::Kill) => continue,
                        Value::Int(_) | Value::Float(_) => continue,
                        other => {
                            return Err(err(format!("join needs a thread handle, got {}", other.describe())));
                        }
                    };
                    if matches!(op, Op::Join) {
                        if id == th.id {
                            return Err(err("a thread cannot join itself".into()));
                        }
                        th.wait = Wait::Join(id);
                    } else {
                        self.arm.abandon(id, KILL_DECEL_RAD_S2);
                        if id == th.id {
                            th.ended = true;
                        } else if let Some(t) = self.threads.iter_mut().find(|t| t.id == id) {
                            t.ended = true;
                        }
                    }
                }
                Op::Pop => {
                    th.stack.pop();
                }
                Op::Return => {
                    let v = pop(th, line)?;
                    th.frames.pop();
                    if th.frames.is_empty() {
                        th.ended = true;
                    } else {
                        th.stack.push(v);
                    }
                }
                Op::Halt => {
                    self.status = Status::Finished;
                    th.ended = true;
                }
            }
            if th.ended || th.wait != Wait::Ready {
                return Ok(());
            }
        }
    }

    /// The variable an assignment writes (URScript's scoping rules); `create` allows a new one.
    fn slot<'a>(
        &'a mut self,
        th: &'a mut Thread,
        name: &str,
        scope: Scope,
        create: bool,
    ) -> Result<&'a mut Value, String> {
        let frame = th.frames.last_mut().ok_or("no frame")?;
        let global = match scope {
            Scope::Global => true,
            Scope::Local => frame.program_body,
            Scope::Free => frame.program_body || (!frame.locals.contains_key(name) && self.globals.contains_key(name)),
        };
        let map = if global { &mut self.globals } else { &mut frame.locals };
        if create {
            Ok(map.entry(name.to_string()).or_insert(Value::Void))
        } else {
            map.get_mut(name).ok_or_else(|| format!("variable `{name}` is not defined"))
        }
    }
}

fn placeholder() -> Thread {
    Thread {
        id: u64::MAX,
        frames: Vec::new(),
        stack: Vec::new(),
        wait: Wait::Ready,
        ended: true,
        blocked_since: None,
        busy_frames: 0,
        socket_io: false,
        last_line: 0,
    }
}

fn pop(th: &mut Thread, line: u32) -> Result<Value, ScriptError> {
    th.stack.pop().ok_or(ScriptError { line, message: "stack underflow".into() })
}

fn set_pc(th: &mut Thread, to: usize) {
    if let Some(f) = th.frames.last_mut() {
        f.pc = to;
    }
}

/// A user function's locals from its arguments and defaults.
fn bind(f: &Function, args: Vec<Value>, kwargs: Vec<(String, Value)>) -> Result<HashMap<String, Value>, String> {
    if args.len() > f.params.len() {
        return Err(format!("{} takes {} arguments, {} given", f.name, f.params.len(), args.len()));
    }
    let mut locals: HashMap<String, Value> = f.params.iter().cloned().zip(args).collect();
    for (k, v) in kwargs {
        if !f.params.contains(&k) {
            return Err(format!("{} has no parameter `{k}`", f.name));
        }
        locals.insert(k, v);
    }
    for (p, d) in f.params.iter().zip(&f.defaults) {
        if !locals.contains_key(p) {
            let v = d.clone().ok_or_else(|| format!("{}: missing argument `{p}`", f.name))?;
            locals.insert(p.clone(), v);
        }
    }
    Ok(locals)
}
