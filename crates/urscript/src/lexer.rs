//! URScript tokens: names, numbers, strings, operators and line ends, each with its line number.
//!
//! `#` starts a comment to the end of the line. Line ends inside `()` or `[]` are skipped, so a
//! list may span lines. A UR controller's version-gated lines (`$5.0 ...`) are filtered by the
//! client (SDU `ur_rtde` strips them before upload); a `$` here is an error.

use super::ScriptError;

/// One token.
#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    /// A name or keyword (`def`, `movej`, `True`, ...).
    Name(String),
    /// An integer literal.
    Int(i64),
    /// A floating-point literal.
    Float(f64),
    /// A string literal (quotes removed).
    Str(String),
    /// An operator or punctuation: `( ) [ ] , : = == != < <= > >= + - * / %`.
    Op(&'static str),
    /// The end of a statement line.
    Newline,
}

/// A token and the line it is on (1-based).
#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    /// The token.
    pub tok: Tok,
    /// Line number, 1-based.
    pub line: u32,
}

const OPS: [&str; 18] = ["==", "!=", "<=", ">=", "(", ")", "[", "]", ",", ":", "=", "<", ">", "+", "-", "*", "/", "%"];

/// Splits `text` into tokens; an error names the line and the character it cannot read.
pub fn lex(text: &str) -> Result<Vec<Token>, ScriptError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let (mut i, mut line, mut depth) = (0usize, 1u32, 0usize);
    let err = |line: u32, what: String| ScriptError { line, message: what };
    while i < chars.len() {
        let c = chars[i];
        match c {
            '\n' => {
                if depth == 0 && out.last().is_some_and(|t: &Token| t.tok != Tok::Newline) {
                    out.push(Token { tok: Tok::Newline, line });
                }
                line += 1;
                i += 1;
            }
            ' ' | '\t' | '\r' => i += 1,
            '#' => {
                while i < chars.len() && chars[i] != '\n' {
                    i += 1;
                }
            }
            '"' | '\'' => {
                let start = i + 1;
                let mut j = start;
                while j < chars.len() && chars[j] != c && chars[j] != '\n' {
                    j += 1;
                }
                if j >= chars.len() || chars[j] != c {
                    return Err(err(line, "unterminated string".into()));
                }
                out.push(Token { tok: Tok::Str(chars[start..j].iter().collect()), line });
                i = j + 1;
            }
            c if c.is_ascii_digit() || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit)) => {
                let start = i;
                let mut float = false;
                while i < chars.len() {
                    let d = chars[i];
                    if d.is_ascii_digit() {
                        i += 1;
                    } else if d == '.' && !float {
                        float = true;
                        i += 1;
                    } else if (d == 'e' || d == 'E')
                        && (chars.get(i + 1).is_some_and(char::is_ascii_digit)
                            || (matches!(chars.get(i + 1), Some('+' | '-'))
                                && chars.get(i + 2).is_some_and(char::is_ascii_digit)))
                    {
                        float = true;
                        i += 2;
                    } else {
                        break;
                    }
                }
                let s: String = chars[start..i].iter().collect();
                let tok = if float {
                    Tok::Float(s.parse().map_err(|_| err(line, format!("bad number {s}")))?)
                } else {
                    match s.parse::<i64>() {
                        Ok(v) => Tok::Int(v),
                        Err(_) => Tok::Float(s.parse().map_err(|_| err(line, format!("bad number {s}")))?),
                    }
                };
                out.push(Token { tok, line });
            }
            c if c.is_alphabetic() || c == '_' => {
                let start = i;
                while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                    i += 1;
                }
                out.push(Token { tok: Tok::Name(chars[start..i].iter().collect()), line });
            }
            _ => {
                let rest: String = chars[i..chars.len().min(i + 2)].iter().collect();
                let Some(op) = OPS.iter().find(|op| rest.starts_with(**op)) else {
                    return Err(err(line, format!("unexpected character {c:?}")));
                };
                match *op {
                    "(" | "[" => depth += 1,
                    ")" | "]" => depth = depth.saturating_sub(1),
                    _ => {}
                }
                out.push(Token { tok: Tok::Op(op), line });
                i += op.len();
            }
        }
    }
    if out.last().is_some_and(|t| t.tok != Tok::Newline) {
        out.push(Token { tok: Tok::Newline, line });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<Tok> {
        lex(s).unwrap().into_iter().map(|t| t.tok).collect()
    }

    #[test]
    fn numbers_names_strings_and_operators() {
        assert_eq!(
            toks("x = -1.5e-3 # c\ny<=2"),
            vec![
                Tok::Name("x".into()),
                Tok::Op("="),
                Tok::Op("-"),
                Tok::Float(1.5e-3),
                Tok::Newline,
                Tok::Name("y".into()),
                Tok::Op("<="),
                Tok::Int(2),
                Tok::Newline
            ]
        );
        assert_eq!(toks("textmsg(\"a # b\")")[2], Tok::Str("a # b".into()));
    }

    #[test]
    fn line_ends_inside_brackets_are_skipped_and_lines_are_counted() {
        let t = lex("a = [1,\n 2]\n\nb = 3\n").unwrap();
        assert_eq!(t.iter().filter(|t| t.tok == Tok::Newline).count(), 2);
        assert_eq!(t.iter().find(|t| t.tok == Tok::Name("b".into())).unwrap().line, 4);
    }

    #[test]
    fn errors_name_the_line() {
        let e = lex("a = 1\nb = $5\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(lex("x = \"open").is_err());
    }
}
