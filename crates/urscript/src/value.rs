//! URScript values and their arithmetic: numbers (int and float), booleans, strings, lists,
//! poses (`p[x, y, z, rx, ry, rz]`) and thread handles.
//!
//! Arithmetic follows the URScript manual where it says: int op int stays int for `+ - * %`,
//! `/` always gives a float (our choice: the manual's examples divide floats only); lists and poses
//! add and subtract element-wise and scale by a number (poses only where the manual's `pose_add`
//! would not be meant: element-wise, as the controller does for `p + p`).

use std::fmt;

/// A runtime value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// `True` / `False`.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A float.
    Float(f64),
    /// A string.
    Str(String),
    /// A list (`[...]`), any element types.
    List(Vec<Value>),
    /// A pose: position \[m\] and rotation vector \[rad\].
    Pose([f64; 6]),
    /// A handle returned by `run`.
    Thread(u64),
    /// What a function without `return` value gives.
    Void,
}

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `%`
    Rem,
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
    /// `xor` on booleans.
    Xor,
}

impl Value {
    /// The type's name in error messages.
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::Bool(_) => "bool",
            Value::Int(_) => "int",
            Value::Float(_) => "float",
            Value::Str(_) => "string",
            Value::List(_) => "list",
            Value::Pose(_) => "pose",
            Value::Thread(_) => "thread",
            Value::Void => "void",
        }
    }

    /// The number, if this is one (booleans are not).
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Value::Int(i) => Some(i as f64),
            Value::Float(f) => Some(f),
            _ => None,
        }
    }

    /// The number or an error naming `what`.
    pub fn num(&self, what: &str) -> Result<f64, String> {
        self.as_f64().ok_or_else(|| format!("{what} must be a number, got {}", self.type_name()))
    }

    /// The truth of a condition: booleans, and numbers (non-zero is true).
    pub fn truthy(&self) -> Result<bool, String> {
        match *self {
            Value::Bool(b) => Ok(b),
            Value::Int(i) => Ok(i != 0),
            Value::Float(f) => Ok(f != 0.0),
            _ => Err(format!("a condition must be a bool, got {}", self.type_name())),
        }
    }

    /// Six numbers from a list or pose (joint positions, speeds, a pose) or an error naming `what`.
    pub fn six(&self, what: &str) -> Result<[f64; 6], String> {
        match self {
            Value::Pose(p) => Ok(*p),
            Value::List(l) if l.len() == 6 => {
                let mut out = [0.0; 6];
                for (o, v) in out.iter_mut().zip(l) {
                    *o = v.num(what)?;
                }
                Ok(out)
            }
            other => Err(format!("{what} must be a list of 6 numbers or a pose, got {}", other.describe())),
        }
    }

    /// A list of six floats.
    pub fn list6(v: [f64; 6]) -> Value {
        Value::List(v.iter().map(|&x| Value::Float(x)).collect())
    }

    /// A short description for error messages (type, and length of a list).
    pub fn describe(&self) -> String {
        match self {
            Value::List(l) => format!("a list of {}", l.len()),
            other => format!("a {}", other.type_name()),
        }
    }

    /// `self[index]`.
    pub fn index(&self, index: &Value) -> Result<Value, String> {
        let i = index_of(index)?;
        match self {
            Value::List(l) => l.get(i).cloned().ok_or_else(|| format!("index {i} out of range (length {})", l.len())),
            Value::Pose(p) => p.get(i).map(|&v| Value::Float(v)).ok_or_else(|| format!("pose index {i} out of range")),
            other => Err(format!("cannot index {}", other.describe())),
        }
    }

    /// `self[index] = value`.
    pub fn set_index(&mut self, index: &Value, value: Value) -> Result<(), String> {
        let i = index_of(index)?;
        match self {
            Value::List(l) => {
                let len = l.len();
                *l.get_mut(i).ok_or_else(|| format!("index {i} out of range (length {len})"))? = value;
                Ok(())
            }
            Value::Pose(p) => {
                let v = value.num("a pose element")?;
                *p.get_mut(i).ok_or_else(|| format!("pose index {i} out of range"))? = v;
                Ok(())
            }
            other => Err(format!("cannot index {}", other.describe())),
        }
    }

    /// `-self`.
    pub fn neg(&self) -> Result<Value, String> {
        match self {
            Value::Int(i) => Ok(Value::Int(i.wrapping_neg())),
            Value::Float(f) => Ok(Value::Float(-f)),
            Value::Pose(p) => Ok(Value::Pose(p.map(|v| -v))),
            Value::List(l) => Ok(Value::List(l.iter().map(Value::neg).collect::<Result<_, _>>()?)),
            other => Err(format!("cannot negate {}", other.describe())),
        }
    }

    /// `self op other`.
    pub fn binary(&self, op: BinOp, other: &Value) -> Result<Value, String> {
        use Value::*;
        match op {
            BinOp::Eq => return Ok(Bool(self.equals(other))),
            BinOp::Ne => return Ok(Bool(!self.equals(other))),
            BinOp::Xor => return Ok(Bool(self.truthy()? ^ other.truthy()?)),
            BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => {
                let (a, b) = (self.num("a comparison operand")?, other.num("a comparison operand")?);
                return Ok(Bool(match op {
                    BinOp::Lt => a < b,
                    BinOp::Le => a <= b,
                    BinOp::Gt => a > b,
                    _ => a >= b,
                }));
            }
            _ => {}
        }
        match (self, other) {
            (Int(a), Int(b)) => match op {
                BinOp::Add => Ok(Int(a.wrapping_add(*b))),
                BinOp::Sub => Ok(Int(a.wrapping_sub(*b))),
                BinOp::Mul => Ok(Int(a.wrapping_mul(*b))),
                BinOp::Div if *b == 0 => Err("division by zero".into()),
                BinOp::Div => Ok(Float(*a as f64 / *b as f64)),
                BinOp::Rem if *b == 0 => Err("modulo by zero".into()),
                _ => Ok(Int(a.wrapping_rem(*b))),
            },
            (Int(_) | Float(_), Int(_) | Float(_)) => {
                let (a, b) = (self.as_f64().unwrap_or(0.0), other.as_f64().unwrap_or(0.0));
                match op {
                    BinOp::Add => Ok(Float(a + b)),
                    BinOp::Sub => Ok(Float(a - b)),
                    BinOp::Mul => Ok(Float(a * b)),
                    BinOp::Div if b == 0.0 => Err("division by zero".into()),
                    BinOp::Div => Ok(Float(a / b)),
                    _ => Ok(Float(a % b)),
                }
            }
            (Pose(_) | List(_), Pose(_) | List(_)) if matches!(op, BinOp::Add | BinOp::Sub) => {
                let (a, b) = (self.elements(), other.elements());
                if a.len() != b.len() {
                    return Err(format!("cannot combine {} and {}", self.describe(), other.describe()));
                }
                let items = a.iter().zip(&b).map(|(x, y)| x.binary(op, y)).collect::<Result<Vec<_>, _>>()?;
                Ok(self.rebuild(items))
            }
            (Pose(_) | List(_), Int(_) | Float(_)) if matches!(op, BinOp::Mul | BinOp::Div) => {
                let items = self.elements().iter().map(|x| x.binary(op, other)).collect::<Result<Vec<_>, _>>()?;
                Ok(self.rebuild(items))
            }
            (Int(_) | Float(_), Pose(_) | List(_)) if op == BinOp::Mul => other.binary(op, self),
            _ => Err(format!("unsupported operands for {op:?}: {} and {}", self.describe(), other.describe())),
        }
    }

    fn elements(&self) -> Vec<Value> {
        match self {
            Value::Pose(p) => p.iter().map(|&v| Value::Float(v)).collect(),
            Value::List(l) => l.clone(),
            other => vec![other.clone()],
        }
    }

    fn rebuild(&self, items: Vec<Value>) -> Value {
        match self {
            Value::Pose(_) => Value::Pose(std::array::from_fn(|i| items[i].as_f64().unwrap_or(0.0))),
            _ => Value::List(items),
        }
    }

    fn equals(&self, other: &Value) -> bool {
        match (self.as_f64(), other.as_f64()) {
            (Some(a), Some(b)) => a == b,
            _ => match (self, other) {
                (Value::List(a), Value::List(b)) => a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.equals(y)),
                _ => self == other,
            },
        }
    }
}

fn index_of(index: &Value) -> Result<usize, String> {
    let i = index.num("an index")?;
    if i < 0.0 || i.fract() != 0.0 || !i.is_finite() {
        return Err(format!("index {i} is not a non-negative integer"));
    }
    Ok(i as usize)
}

fn float(f: f64) -> String {
    if f.fract() == 0.0 && f.abs() < 1e15 { format!("{f:.1}") } else { format!("{f}") }
}

impl fmt::Display for Value {
    /// As `textmsg` and `to_str` print it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{}", if *b { "True" } else { "False" }),
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{}", float(*x)),
            Value::Str(s) => write!(f, "{s}"),
            Value::List(l) => {
                let items: Vec<String> = l.iter().map(|v| v.to_string()).collect();
                write!(f, "[{}]", items.join(", "))
            }
            Value::Pose(p) => {
                let items: Vec<String> = p.iter().map(|v| float(*v)).collect();
                write!(f, "p[{}]", items.join(", "))
            }
            Value::Thread(id) => write!(f, "<thread {id}>"),
            Value::Void => write!(f, "None"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_keeps_ints_and_divides_to_floats() {
        assert_eq!(Value::Int(7).binary(BinOp::Add, &Value::Int(2)), Ok(Value::Int(9)));
        assert_eq!(Value::Int(7).binary(BinOp::Rem, &Value::Int(4)), Ok(Value::Int(3)));
        assert_eq!(Value::Int(7).binary(BinOp::Div, &Value::Int(2)), Ok(Value::Float(3.5)));
        assert!(Value::Int(1).binary(BinOp::Div, &Value::Int(0)).is_err());
        assert_eq!(Value::Int(2).binary(BinOp::Eq, &Value::Float(2.0)), Ok(Value::Bool(true)));
        assert!(Value::Str("a".into()).binary(BinOp::Lt, &Value::Int(1)).is_err());
    }

    #[test]
    fn lists_and_poses_combine_element_wise_and_print_as_the_controller_does() {
        let p = Value::Pose([1.0, 2.0, 3.0, 0.0, 0.0, 0.5]);
        assert_eq!(p.binary(BinOp::Mul, &Value::Int(2)).unwrap(), Value::Pose([2.0, 4.0, 6.0, 0.0, 0.0, 1.0]));
        assert_eq!(p.to_string(), "p[1.0, 2.0, 3.0, 0.0, 0.0, 0.5]");
        let l = Value::List(vec![Value::Int(1), Value::Bool(true)]);
        assert_eq!(l.to_string(), "[1, True]");
        assert!(l.index(&Value::Int(2)).is_err());
        assert!(l.index(&Value::Float(0.5)).is_err());
        let mut m = Value::list6([0.0; 6]);
        m.set_index(&Value::Int(5), Value::Int(3)).unwrap();
        assert_eq!(m.six("q").unwrap()[5], 3.0);
    }
}
