//! The syntax tree compiled to a small stack code, so that a thread can stop at any call that
//! waits for the controller's clock (`sync`, `sleep`, the motions) and resume there on a later
//! tick: a tree-walking evaluator could not suspend in the middle of an expression such as
//! `x = f()` where `f` moves the arm.
//!
//! Every `def` and `thread`, nested or not, is compiled into one table by name (a nested
//! definition is visible everywhere, as in URScript, where functions are declared before the
//! program runs).

use super::ScriptError;
use super::ast::{Expr, FuncDef, Scope, Stmt, StmtKind};
use super::value::{BinOp, Value};
use std::collections::HashMap;
use std::sync::Arc;

/// One instruction.
#[derive(Debug, Clone, PartialEq)]
pub enum Op {
    /// Push a value.
    Const(Value),
    /// Push a variable's value.
    Load(String),
    /// Pop into a variable.
    Store(String, Scope),
    /// Pop a value, then `n` indices (pushed outermost first), and store into `name[i0][i1]...`.
    StoreIndexed(String, usize, Scope),
    /// Pop index and container, push the element.
    Index,
    /// Pop `n` values into a list.
    List(usize),
    /// Pop `n` numbers into a pose.
    Pose(usize),
    /// Negate the top.
    Neg,
    /// Logical not of the top.
    Not,
    /// Pop two, push `a op b`.
    Bin(BinOp),
    /// Go to an instruction.
    Jump(usize),
    /// Pop; go to the instruction if false.
    JumpIfFalse(usize),
    /// `and`: if the top is false keep it and go to the instruction, else pop it.
    AndJump(usize),
    /// `or`: if the top is true keep it and go to the instruction, else pop it.
    OrJump(usize),
    /// Pop positional then keyword arguments; call; push the result.
    Call(String, usize, Vec<String>),
    /// Start a thread; push its handle.
    Run(String),
    /// Pop a handle and end that thread.
    Kill,
    /// Pop a handle and wait for that thread to end.
    Join,
    /// Drop the top.
    Pop,
    /// Pop the return value and return.
    Return,
    /// End the program.
    Halt,
}

/// A compiled `def` or `thread`.
#[derive(Debug, Clone, PartialEq)]
pub struct Function {
    /// Its name.
    pub name: String,
    /// Parameter names.
    pub params: Vec<String>,
    /// Default values, one per parameter.
    pub defaults: Vec<Option<Value>>,
    /// The code.
    pub code: Vec<Op>,
    /// The source line of each instruction.
    pub lines: Vec<u32>,
    /// A `thread` (started with `run`) rather than a `def`.
    pub is_thread: bool,
}

/// A compiled program: its body and every function and thread it defines.
#[derive(Debug, Clone, PartialEq)]
pub struct Compiled {
    /// The program's own body (the outermost `def`).
    pub main: Arc<Function>,
    /// Every nested `def` and `thread` by name.
    pub functions: HashMap<String, Arc<Function>>,
}

/// Compiles a parsed program.
pub fn compile(program: &FuncDef) -> Result<Compiled, ScriptError> {
    let mut functions = HashMap::new();
    let main = compile_function(program, &mut functions)?;
    Ok(Compiled { main: Arc::new(main), functions })
}

fn compile_function(def: &FuncDef, table: &mut HashMap<String, Arc<Function>>) -> Result<Function, ScriptError> {
    let mut c = Emitter { code: Vec::new(), lines: Vec::new(), loops: Vec::new(), line: def.line };
    c.block(&def.body, table)?;
    c.emit(Op::Const(Value::Void));
    c.emit(Op::Return);
    Ok(Function {
        name: def.name.clone(),
        params: def.params.clone(),
        defaults: def.defaults.clone(),
        code: c.code,
        lines: c.lines,
        is_thread: def.is_thread,
    })
}

/// Jumps to patch when a loop ends (`break`) and where `continue` goes.
struct Loop {
    start: usize,
    breaks: Vec<usize>,
}

struct Emitter {
    code: Vec<Op>,
    lines: Vec<u32>,
    loops: Vec<Loop>,
    line: u32,
}

impl Emitter {
    fn emit(&mut self, op: Op) -> usize {
        self.code.push(op);
        self.lines.push(self.line);
        self.code.len() - 1
    }

    fn patch(&mut self, at: usize, to: usize) {
        match &mut self.code[at] {
            Op::Jump(t) | Op::JumpIfFalse(t) | Op::AndJump(t) | Op::OrJump(t) => *t = to,
            _ => {}
        }
    }

    fn block(&mut self, stmts: &[Stmt], table: &mut HashMap<String, Arc<Function>>) -> Result<(), ScriptError> {
        for s in stmts {
            self.line = s.line;
            self.statement(s, table)?;
        }
        Ok(())
    }

    fn statement(&mut self, s: &Stmt, table: &mut HashMap<String, Arc<Function>>) -> Result<(), ScriptError> {
        let error = |message: &str| ScriptError { line: s.line, message: message.into() };
        match &s.kind {
            StmtKind::Expr(e) => {
                self.expr(e);
                self.emit(Op::Pop);
            }
            StmtKind::Assign { name, indices, value, scope } => {
                for i in indices {
                    self.expr(i);
                }
                self.expr(value);
                if indices.is_empty() {
                    self.emit(Op::Store(name.clone(), *scope));
                } else {
                    self.emit(Op::StoreIndexed(name.clone(), indices.len(), *scope));
                }
            }
            StmtKind::If { branches, otherwise } => {
                let mut ends = Vec::new();
                for (cond, body) in branches {
                    self.expr(cond);
                    let skip = self.emit(Op::JumpIfFalse(0));
                    self.block(body, table)?;
                    ends.push(self.emit(Op::Jump(0)));
                    let next = self.code.len();
                    self.patch(skip, next);
                }
                self.block(otherwise, table)?;
                let end = self.code.len();
                for e in ends {
                    self.patch(e, end);
                }
            }
            StmtKind::While(cond, body) => {
                let start = self.code.len();
                self.expr(cond);
                let exit = self.emit(Op::JumpIfFalse(0));
                self.loops.push(Loop { start, breaks: vec![exit] });
                self.block(body, table)?;
                self.emit(Op::Jump(start));
                let end = self.code.len();
                let l = self.loops.pop().expect("pushed above");
                for b in l.breaks {
                    self.patch(b, end);
                }
            }
            StmtKind::Return(e) => {
                match e {
                    Some(e) => self.expr(e),
                    None => {
                        self.emit(Op::Const(Value::Void));
                    }
                }
                self.emit(Op::Return);
            }
            StmtKind::Break => {
                let at = self.emit(Op::Jump(0));
                self.loops.last_mut().ok_or_else(|| error("`break` outside a loop"))?.breaks.push(at);
            }
            StmtKind::Continue => {
                let start = self.loops.last().ok_or_else(|| error("`continue` outside a loop"))?.start;
                self.emit(Op::Jump(start));
            }
            StmtKind::Halt => {
                self.emit(Op::Halt);
            }
            StmtKind::Kill(e) | StmtKind::Join(e) => {
                self.expr(e);
                self.emit(if matches!(s.kind, StmtKind::Kill(_)) { Op::Kill } else { Op::Join });
            }
            StmtKind::Nop => {}
            StmtKind::Def(def) => {
                let f = compile_function(def, table)?;
                table.insert(def.name.clone(), Arc::new(f));
            }
        }
        Ok(())
    }

    fn expr(&mut self, e: &Expr) {
        match e {
            Expr::Lit(v) => {
                self.emit(Op::Const(v.clone()));
            }
            Expr::Name(n) => {
                self.emit(Op::Load(n.clone()));
            }
            Expr::List(items) | Expr::Pose(items) => {
                for i in items {
                    self.expr(i);
                }
                self.emit(if matches!(e, Expr::List(_)) { Op::List(items.len()) } else { Op::Pose(items.len()) });
            }
            Expr::Index(a, i) => {
                self.expr(a);
                self.expr(i);
                self.emit(Op::Index);
            }
            Expr::Call { name, args, kwargs } => {
                for a in args {
                    self.expr(a);
                }
                for (_, v) in kwargs {
                    self.expr(v);
                }
                self.emit(Op::Call(name.clone(), args.len(), kwargs.iter().map(|(k, _)| k.clone()).collect()));
            }
            Expr::Run(name) => {
                self.emit(Op::Run(name.clone()));
            }
            Expr::Neg(a) => {
                self.expr(a);
                self.emit(Op::Neg);
            }
            Expr::Not(a) => {
                self.expr(a);
                self.emit(Op::Not);
            }
            Expr::Binary(op, a, b) => {
                self.expr(a);
                self.expr(b);
                self.emit(Op::Bin(*op));
            }
            Expr::And(a, b) | Expr::Or(a, b) => {
                self.expr(a);
                let j = self.emit(if matches!(e, Expr::And(..)) { Op::AndJump(0) } else { Op::OrJump(0) });
                self.expr(b);
                let end = self.code.len();
                self.patch(j, end);
            }
        }
    }
}
