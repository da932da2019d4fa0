//! `${name}` substitution for the MJCF templates in models/.

use super::PhysicsError;

/// Replaces every `${key}` in `text` by its value; a placeholder left without a value is an error
/// naming it (a template and its filler out of step), never silently kept.
pub fn render(text: &str, values: &[(&str, String)]) -> Result<String, PhysicsError> {
    let mut out = text.to_string();
    for (key, value) in values {
        out = out.replace(&format!("${{{key}}}"), value);
    }
    match out.find("${") {
        None => Ok(out),
        Some(at) => {
            let end = out[at..].find('}').map_or(out.len(), |e| at + e + 1);
            Err(PhysicsError::Template { placeholder: out[at..end].to_string() })
        }
    }
}

/// The inner text of the first `<tag>...</tag>` section of an MJCF part ("" when absent).
pub fn section<'a>(text: &'a str, tag: &str) -> &'a str {
    let open = format!("<{tag}>");
    let close = format!("</{tag}>");
    match (text.find(&open), text.rfind(&close)) {
        (Some(a), Some(b)) if b > a => &text[a + open.len()..b],
        _ => "",
    }
}

/// Formats a float for MJCF with full precision.
pub fn num(x: f64) -> String {
    format!("{x:?}")
}

/// Formats several floats separated by spaces.
pub fn nums(xs: &[f64]) -> String {
    xs.iter().map(|x| num(*x)).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_and_reports_leftovers() {
        assert_eq!(render("a ${x} b", &[("x", "1".into())]).unwrap(), "a 1 b");
        let err = render("a ${x} ${y}", &[("x", "1".into())]).unwrap_err();
        assert!(err.to_string().contains("${y}"), "{err}");
    }

    #[test]
    fn finds_sections() {
        assert_eq!(section("<m><worldbody>X</worldbody></m>", "worldbody"), "X");
        assert_eq!(section("<m></m>", "tendon"), "");
    }
}
