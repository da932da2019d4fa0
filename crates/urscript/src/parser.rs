//! Recursive-descent parser: tokens to a [`FuncDef`] for the program's `def name(): ... end`.
//!
//! Precedence, loosest first: `or`, `xor`, `and`, `not`, comparisons, `+ -`, `* / %`, unary `-`,
//! calls and indexing. `p[a, b, ...]` is a pose literal; `p[i]` (one element) indexes a variable
//! named `p` (SDU ur_rtde's control script names a parameter `p`). Nesting deeper than
//! [`MAX_DEPTH`] is an error rather than a stack overflow.

use super::ScriptError;
use super::ast::{Expr, FuncDef, Scope, Stmt, StmtKind};
use super::lexer::{Tok, Token, lex};
use super::value::{BinOp, Value};

/// Deepest nesting of blocks and expressions accepted.
pub const MAX_DEPTH: usize = 200;

/// Parses a complete program: one `def name(): ... end`, or a secondary program `sec name(): ...
/// end` (comments and blank lines around it).
pub fn parse_program(text: &str) -> Result<FuncDef, ScriptError> {
    let tokens = lex(text)?;
    let mut p = Parser { tokens, pos: 0, depth: 0 };
    p.skip_newlines();
    let line = p.line();
    if !p.at_name("def") && !p.at_name("sec") {
        return Err(p.error("a program starts with `def name():` or `sec name():`"));
    }
    let secondary = p.at_name("sec");
    let mut main = p.funcdef()?;
    main.secondary = secondary;
    if !main.params.is_empty() {
        return Err(ScriptError { line, message: "the program's def takes no parameters".into() });
    }
    p.skip_newlines();
    if p.pos < p.tokens.len() {
        return Err(p.error("nothing may follow the program's final `end`"));
    }
    Ok(main)
}

struct Parser {
    tokens: Vec<Token>,
    pos: usize,
    depth: usize,
}

const BLOCK_END: [&str; 3] = ["end", "elif", "else"];

/// Names that cannot be variables.
const KEYWORDS: [&str; 17] = [
    "end", "elif", "else", "def", "thread", "if", "while", "return", "global", "local", "break", "continue", "halt",
    "kill", "join", "and", "or",
];

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.tokens.get(self.pos).map(|t| &t.tok)
    }

    fn peek_at(&self, k: usize) -> Option<&Tok> {
        self.tokens.get(self.pos + k).map(|t| &t.tok)
    }

    fn line(&self) -> u32 {
        self.tokens.get(self.pos).or(self.tokens.last()).map_or(1, |t| t.line)
    }

    fn error(&self, message: &str) -> ScriptError {
        let found = match self.peek() {
            None => "the end of the program".to_string(),
            Some(Tok::Newline) => "the end of the line".to_string(),
            Some(Tok::Name(n)) => format!("`{n}`"),
            Some(Tok::Int(i)) => format!("`{i}`"),
            Some(Tok::Float(f)) => format!("`{f}`"),
            Some(Tok::Str(s)) => format!("\"{s}\""),
            Some(Tok::Op(o)) => format!("`{o}`"),
        };
        ScriptError { line: self.line(), message: format!("{message} (found {found})") }
    }

    fn at_name(&self, name: &str) -> bool {
        matches!(self.peek(), Some(Tok::Name(n)) if n == name)
    }

    fn at_op(&self, op: &str) -> bool {
        matches!(self.peek(), Some(Tok::Op(o)) if *o == op)
    }

    fn eat_op(&mut self, op: &str) -> bool {
        let at = self.at_op(op);
        if at {
            self.pos += 1;
        }
        at
    }

    fn expect_op(&mut self, op: &str) -> Result<(), ScriptError> {
        if self.eat_op(op) { Ok(()) } else { Err(self.error(&format!("expected `{op}`"))) }
    }

    fn expect_name(&mut self) -> Result<String, ScriptError> {
        match self.peek() {
            Some(Tok::Name(n)) => {
                let n = n.clone();
                self.pos += 1;
                Ok(n)
            }
            _ => Err(self.error("expected a name")),
        }
    }

    /// The end of a statement. URScript does not need a line end there: the controller takes
    /// `global a = # comment` with the value on the next line, and two statements on one line,
    /// which SDU ur_rtde's control script relies on (its register-offset injection leaves
    /// `0    global reg_offset_int = ...`).
    fn expect_newline(&mut self) -> Result<(), ScriptError> {
        self.skip_newlines();
        Ok(())
    }

    fn skip_newlines(&mut self) {
        while self.peek() == Some(&Tok::Newline) {
            self.pos += 1;
        }
    }

    fn enter(&mut self) -> Result<(), ScriptError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH { Err(self.error("nesting too deep")) } else { Ok(()) }
    }

    fn funcdef(&mut self) -> Result<FuncDef, ScriptError> {
        let line = self.line();
        let is_thread = self.at_name("thread");
        self.pos += 1;
        let name = self.expect_name()?;
        self.expect_op("(")?;
        let (mut params, mut defaults) = (Vec::new(), Vec::new());
        while !self.at_op(")") {
            params.push(self.expect_name()?);
            defaults.push(if self.eat_op("=") {
                let e = self.expr()?;
                Some(constant(&e).ok_or_else(|| self.error("a parameter default must be a literal"))?)
            } else {
                None
            });
            if !self.eat_op(",") {
                break;
            }
        }
        self.expect_op(")")?;
        self.expect_op(":")?;
        if is_thread && !params.is_empty() {
            return Err(ScriptError { line, message: format!("thread {name} cannot take parameters") });
        }
        self.expect_newline()?;
        let body = self.block()?;
        self.end()?;
        Ok(FuncDef { name, params, defaults, body, is_thread, secondary: false, line })
    }

    fn end(&mut self) -> Result<(), ScriptError> {
        if !self.at_name("end") {
            return Err(self.error("expected `end`"));
        }
        self.pos += 1;
        self.expect_newline()
    }

    /// Statements up to (not including) `end`, `elif` or `else`.
    fn block(&mut self) -> Result<Vec<Stmt>, ScriptError> {
        self.enter()?;
        let mut out = Vec::new();
        loop {
            self.skip_newlines();
            match self.peek() {
                None => return Err(self.error("expected `end`")),
                Some(Tok::Name(n)) if BLOCK_END.contains(&n.as_str()) => break,
                _ => out.push(self.statement()?),
            }
        }
        self.depth -= 1;
        Ok(out)
    }

    fn statement(&mut self) -> Result<Stmt, ScriptError> {
        let line = self.line();
        let keyword = match self.peek() {
            Some(Tok::Name(n)) => n.clone(),
            _ => String::new(),
        };
        let simple = |kind| Stmt { kind, line };
        let kind = match keyword.as_str() {
            "def" | "thread" => return Ok(simple(StmtKind::Def(self.funcdef()?))),
            "if" => {
                self.pos += 1;
                let mut branches = Vec::new();
                let mut otherwise = Vec::new();
                loop {
                    let cond = self.expr()?;
                    self.expect_op(":")?;
                    self.expect_newline()?;
                    branches.push((cond, self.block()?));
                    if self.at_name("elif") {
                        self.pos += 1;
                        continue;
                    }
                    if self.at_name("else") {
                        self.pos += 1;
                        self.expect_op(":")?;
                        self.expect_newline()?;
                        otherwise = self.block()?;
                    }
                    break;
                }
                self.end()?;
                return Ok(simple(StmtKind::If { branches, otherwise }));
            }
            "while" => {
                self.pos += 1;
                let cond = self.expr()?;
                self.expect_op(":")?;
                self.expect_newline()?;
                let body = self.block()?;
                self.end()?;
                return Ok(simple(StmtKind::While(cond, body)));
            }
            "return" => {
                self.pos += 1;
                StmtKind::Return(if matches!(self.peek(), Some(Tok::Newline) | None) {
                    None
                } else {
                    Some(self.expr()?)
                })
            }
            "break" | "continue" | "halt" | "pass" | "enter_critical" | "exit_critical" => {
                self.pos += 1;
                match keyword.as_str() {
                    "break" => StmtKind::Break,
                    "continue" => StmtKind::Continue,
                    "halt" => StmtKind::Halt,
                    _ => StmtKind::Nop,
                }
            }
            "kill" | "join" => {
                self.pos += 1;
                let e = self.expr()?;
                if keyword == "kill" { StmtKind::Kill(e) } else { StmtKind::Join(e) }
            }
            "global" | "local" => {
                self.pos += 1;
                let name = self.expect_name()?;
                self.expect_op("=")?;
                let value = self.expr()?;
                let scope = if keyword == "global" { Scope::Global } else { Scope::Local };
                StmtKind::Assign { name, indices: Vec::new(), value, scope }
            }
            "sec" | "for" | "interpreter_mode" => {
                // A `sec` inside a program is not URScript (secondary programs are sent on their own).
                return Err(self.error(&format!("`{keyword}` is not supported by the virtual controller")));
            }
            "end" | "elif" | "else" => return Err(self.error("unexpected block end")),
            _ => {
                let e = self.expr()?;
                if self.eat_op("=") {
                    let value = self.expr()?;
                    let (name, indices) = target(e).ok_or_else(|| ScriptError {
                        line,
                        message: "the left of `=` must be a variable or an indexed variable".into(),
                    })?;
                    StmtKind::Assign { name, indices, value, scope: Scope::Free }
                } else {
                    StmtKind::Expr(e)
                }
            }
        };
        self.expect_newline()?;
        Ok(simple(kind))
    }

    fn expr(&mut self) -> Result<Expr, ScriptError> {
        self.enter()?;
        let e = self.or_expr();
        self.depth -= 1;
        e
    }

    fn or_expr(&mut self) -> Result<Expr, ScriptError> {
        let mut e = self.xor_expr()?;
        while self.at_name("or") {
            self.pos += 1;
            e = Expr::Or(Box::new(e), Box::new(self.xor_expr()?));
        }
        Ok(e)
    }

    fn xor_expr(&mut self) -> Result<Expr, ScriptError> {
        let mut e = self.and_expr()?;
        while self.at_name("xor") {
            self.pos += 1;
            e = Expr::Binary(BinOp::Xor, Box::new(e), Box::new(self.and_expr()?));
        }
        Ok(e)
    }

    fn and_expr(&mut self) -> Result<Expr, ScriptError> {
        let mut e = self.not_expr()?;
        while self.at_name("and") {
            self.pos += 1;
            e = Expr::And(Box::new(e), Box::new(self.not_expr()?));
        }
        Ok(e)
    }

    fn not_expr(&mut self) -> Result<Expr, ScriptError> {
        if self.at_name("not") {
            self.pos += 1;
            self.enter()?;
            let e = Expr::Not(Box::new(self.not_expr()?));
            self.depth -= 1;
            return Ok(e);
        }
        self.comparison()
    }

    fn comparison(&mut self) -> Result<Expr, ScriptError> {
        let mut e = self.additive()?;
        loop {
            let op = match self.peek() {
                Some(Tok::Op("==")) => BinOp::Eq,
                Some(Tok::Op("!=")) => BinOp::Ne,
                Some(Tok::Op("<")) => BinOp::Lt,
                Some(Tok::Op("<=")) => BinOp::Le,
                Some(Tok::Op(">")) => BinOp::Gt,
                Some(Tok::Op(">=")) => BinOp::Ge,
                _ => return Ok(e),
            };
            self.pos += 1;
            e = Expr::Binary(op, Box::new(e), Box::new(self.additive()?));
        }
    }

    fn additive(&mut self) -> Result<Expr, ScriptError> {
        let mut e = self.term()?;
        loop {
            let op = match self.peek() {
                Some(Tok::Op("+")) => BinOp::Add,
                Some(Tok::Op("-")) => BinOp::Sub,
                _ => return Ok(e),
            };
            self.pos += 1;
            e = Expr::Binary(op, Box::new(e), Box::new(self.term()?));
        }
    }

    fn term(&mut self) -> Result<Expr, ScriptError> {
        let mut e = self.unary()?;
        loop {
            let op = match self.peek() {
                Some(Tok::Op("*")) => BinOp::Mul,
                Some(Tok::Op("/")) => BinOp::Div,
                Some(Tok::Op("%")) => BinOp::Rem,
                _ => return Ok(e),
            };
            self.pos += 1;
            e = Expr::Binary(op, Box::new(e), Box::new(self.unary()?));
        }
    }

    fn unary(&mut self) -> Result<Expr, ScriptError> {
        if self.eat_op("-") {
            self.enter()?;
            let inner = self.unary()?;
            self.depth -= 1;
            return Ok(match inner {
                Expr::Lit(Value::Int(i)) => Expr::Lit(Value::Int(i.wrapping_neg())),
                Expr::Lit(Value::Float(f)) => Expr::Lit(Value::Float(-f)),
                other => Expr::Neg(Box::new(other)),
            });
        }
        if self.eat_op("+") {
            self.enter()?;
            let inner = self.unary();
            self.depth -= 1;
            return inner;
        }
        self.postfix()
    }

    fn postfix(&mut self) -> Result<Expr, ScriptError> {
        let mut e = self.primary()?;
        while self.eat_op("[") {
            let i = self.expr()?;
            self.expect_op("]")?;
            e = Expr::Index(Box::new(e), Box::new(i));
        }
        Ok(e)
    }

    fn items(&mut self, close: &str) -> Result<Vec<Expr>, ScriptError> {
        let mut items = Vec::new();
        while !self.at_op(close) {
            items.push(self.expr()?);
            if !self.eat_op(",") {
                break;
            }
        }
        self.expect_op(close)?;
        Ok(items)
    }

    fn primary(&mut self) -> Result<Expr, ScriptError> {
        // An expression may continue on the next line (see `expect_newline`).
        self.skip_newlines();
        if matches!(self.peek(), Some(Tok::Name(n)) if KEYWORDS.contains(&n.as_str())) {
            return Err(self.error("expected an expression"));
        }
        let tok = self.peek().cloned();
        match tok {
            Some(Tok::Int(i)) => {
                self.pos += 1;
                Ok(Expr::Lit(Value::Int(i)))
            }
            Some(Tok::Float(f)) => {
                self.pos += 1;
                Ok(Expr::Lit(Value::Float(f)))
            }
            Some(Tok::Str(s)) => {
                self.pos += 1;
                Ok(Expr::Lit(Value::Str(s)))
            }
            Some(Tok::Op("(")) => {
                self.pos += 1;
                let e = self.expr()?;
                self.expect_op(")")?;
                Ok(e)
            }
            Some(Tok::Op("[")) => {
                self.pos += 1;
                Ok(Expr::List(self.items("]")?))
            }
            Some(Tok::Name(n)) => {
                self.pos += 1;
                match n.as_str() {
                    "True" | "true" => return Ok(Expr::Lit(Value::Bool(true))),
                    "False" | "false" => return Ok(Expr::Lit(Value::Bool(false))),
                    "run" => {
                        let name = self.expect_name()?;
                        self.expect_op("(")?;
                        self.expect_op(")")?;
                        return Ok(Expr::Run(name));
                    }
                    "p" if self.at_op("[") => {
                        self.pos += 1;
                        let mut items = self.items("]")?;
                        return Ok(if items.len() == 1 {
                            Expr::Index(Box::new(Expr::Name(n)), Box::new(items.remove(0)))
                        } else {
                            Expr::Pose(items)
                        });
                    }
                    _ => {}
                }
                if self.eat_op("(") {
                    let (mut args, mut kwargs) = (Vec::new(), Vec::new());
                    while !self.at_op(")") {
                        if let (Some(Tok::Name(k)), Some(Tok::Op("="))) = (self.peek(), self.peek_at(1)) {
                            let k = k.clone();
                            self.pos += 2;
                            kwargs.push((k, self.expr()?));
                        } else if kwargs.is_empty() {
                            args.push(self.expr()?);
                        } else {
                            return Err(self.error("a positional argument after a keyword argument"));
                        }
                        if !self.eat_op(",") {
                            break;
                        }
                    }
                    self.expect_op(")")?;
                    return Ok(Expr::Call { name: n, args, kwargs });
                }
                Ok(Expr::Name(n))
            }
            _ => Err(self.error("expected an expression")),
        }
    }
}

/// A literal value, or a list or pose of them (parameter defaults).
fn constant(e: &Expr) -> Option<Value> {
    match e {
        Expr::Lit(v) => Some(v.clone()),
        Expr::List(items) => items.iter().map(constant).collect::<Option<Vec<_>>>().map(Value::List),
        Expr::Pose(items) if items.len() == 6 => {
            let v = items.iter().map(|i| constant(i)?.as_f64()).collect::<Option<Vec<_>>>()?;
            Some(Value::Pose(std::array::from_fn(|k| v[k])))
        }
        _ => None,
    }
}

/// `a` or `a[i][j]` as an assignment target.
fn target(e: Expr) -> Option<(String, Vec<Expr>)> {
    match e {
        Expr::Name(n) => Some((n, Vec::new())),
        Expr::Index(inner, i) => {
            let (n, mut indices) = target(*inner)?;
            indices.push(*i);
            Some((n, indices))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(src: &str) -> Vec<Stmt> {
        parse_program(&format!("def prog():\n{src}\nend\n")).unwrap().body
    }

    #[test]
    fn statements_and_precedence() {
        let b = body(
            "  x = 1 + 2 * 3\n  if x > 3 and not False:\n    y = p[0, 0, 0.1, 0, 0, 0]\n  elif x == 1:\n    y = 2\n  else:\n    y = -x\n  end",
        );
        assert_eq!(b.len(), 2);
        match &b[0].kind {
            StmtKind::Assign { value: Expr::Binary(BinOp::Add, _, r), .. } => {
                assert!(matches!(**r, Expr::Binary(BinOp::Mul, _, _)))
            }
            other => panic!("{other:?}"),
        }
        match &b[1].kind {
            StmtKind::If { branches, otherwise } => {
                assert_eq!(branches.len(), 2);
                assert_eq!(otherwise.len(), 1);
                assert!(
                    matches!(&branches[0].1[0].kind, StmtKind::Assign { value: Expr::Pose(p), .. } if p.len() == 6)
                );
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(b[1].line, 3);
    }

    #[test]
    fn calls_keywords_threads_indexing_and_p_as_a_variable() {
        let b = body(
            "  x = # a comment, the value on the next line\n  0    y = 2\n  movej(q, a=1.4, v=1.05)\n  h = run t()\n  p[0] = p[0] * 2\n  global g = [1, 2]\n  thread t():\n    sync()\n  end",
        );
        assert!(matches!(&b[0].kind, StmtKind::Assign { name, value: Expr::Lit(Value::Int(0)), .. } if name == "x"));
        assert!(matches!(&b[1].kind, StmtKind::Assign { name, .. } if name == "y"));
        let b = &b[2..];
        assert!(
            matches!(&b[0].kind, StmtKind::Expr(Expr::Call { args, kwargs, .. }) if args.len() == 1 && kwargs.len() == 2)
        );
        assert!(matches!(&b[1].kind, StmtKind::Assign { value: Expr::Run(t), .. } if t == "t"));
        assert!(matches!(&b[2].kind, StmtKind::Assign { name, indices, .. } if name == "p" && indices.len() == 1));
        assert!(matches!(&b[3].kind, StmtKind::Assign { scope: Scope::Global, .. }));
        assert!(matches!(&b[4].kind, StmtKind::Def(FuncDef { is_thread: true, .. })));
    }

    #[test]
    fn errors_name_the_line_and_what_was_expected() {
        for (src, line, what) in [
            ("def prog():\n  x = 1 +\nend\n", 3, "expected an expression"),
            ("def prog():\n  if x\n  end\nend\n", 2, "expected `:`"),
            ("def prog():\n  x = 1\n", 2, "expected `end`"),
            ("x = 1\n", 1, "starts with"),
            ("def prog():\n  for i in x:\n  end\nend\n", 2, "not supported"),
            ("def prog():\nend\ndef other():\nend\n", 3, "nothing may follow"),
            ("def prog():\n  f(a=1, 2)\nend\n", 2, "positional"),
        ] {
            let e = parse_program(src).unwrap_err();
            assert_eq!(e.line, line, "{src}: {e}");
            assert!(e.message.contains(what), "{src}: {e}");
        }
        let deep = format!("def prog():\n  x = {}1{}\nend\n", "(".repeat(5000), ")".repeat(5000));
        assert!(parse_program(&deep).unwrap_err().message.contains("too deep"));
    }
}
