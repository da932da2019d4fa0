//! The syntax tree the parser builds and the compiler reads.

use super::value::{BinOp, Value};

/// An expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A literal.
    Lit(Value),
    /// A variable.
    Name(String),
    /// `[a, b, ...]`.
    List(Vec<Expr>),
    /// `p[x, y, z, rx, ry, rz]`.
    Pose(Vec<Expr>),
    /// `a[i]`.
    Index(Box<Expr>, Box<Expr>),
    /// `f(a, b, k=v)`.
    Call {
        /// Function name.
        name: String,
        /// Positional arguments.
        args: Vec<Expr>,
        /// Keyword arguments, in order.
        kwargs: Vec<(String, Expr)>,
    },
    /// `run t()`: starts a thread, gives its handle.
    Run(String),
    /// `-a`.
    Neg(Box<Expr>),
    /// `not a`.
    Not(Box<Expr>),
    /// `a op b`.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `a and b` (short-circuit).
    And(Box<Expr>, Box<Expr>),
    /// `a or b` (short-circuit).
    Or(Box<Expr>, Box<Expr>),
}

/// Where an assignment stores.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// No qualifier: a global of that name if one exists, else a local (URScript manual,
    /// "Scoping rules"); in the program's own body, a global.
    Free,
    /// `global x = ...`.
    Global,
    /// `local x = ...`.
    Local,
}

/// A statement and its line.
#[derive(Debug, Clone, PartialEq)]
pub struct Stmt {
    /// What it does.
    pub kind: StmtKind,
    /// Line number, 1-based.
    pub line: u32,
}

/// The statements.
#[derive(Debug, Clone, PartialEq)]
pub enum StmtKind {
    /// An expression evaluated for its effect (a call).
    Expr(Expr),
    /// `name[i][j] = value`, with a scope qualifier.
    Assign {
        /// Variable.
        name: String,
        /// Index expressions, outermost first (empty: the whole variable).
        indices: Vec<Expr>,
        /// The value.
        value: Expr,
        /// Qualifier.
        scope: Scope,
    },
    /// `if c: ... elif c: ... else: ... end`.
    If {
        /// Conditions and their blocks.
        branches: Vec<(Expr, Vec<Stmt>)>,
        /// The `else` block (maybe empty).
        otherwise: Vec<Stmt>,
    },
    /// `while c: ... end`.
    While(Expr, Vec<Stmt>),
    /// `return` or `return value`.
    Return(Option<Expr>),
    /// `break`.
    Break,
    /// `continue`.
    Continue,
    /// `halt`: ends the program.
    Halt,
    /// `kill handle`.
    Kill(Expr),
    /// `join handle`.
    Join(Expr),
    /// `enter_critical`, `exit_critical`, `pass`: nothing to do for a cooperative scheduler that
    /// only switches threads where a thread waits.
    Nop,
    /// A nested `def` or `thread`.
    Def(FuncDef),
}

/// A `def` or `thread`.
#[derive(Debug, Clone, PartialEq)]
pub struct FuncDef {
    /// Its name.
    pub name: String,
    /// Parameter names.
    pub params: Vec<String>,
    /// Default values (literals), one per parameter.
    pub defaults: Vec<Option<Value>>,
    /// Body.
    pub body: Vec<Stmt>,
    /// `thread` rather than `def`.
    pub is_thread: bool,
    /// A secondary program (`sec name():`, the outermost definition only): it runs beside the
    /// main program and may not consume time.
    pub secondary: bool,
    /// Line of the header.
    pub line: u32,
}
