//! Output folders derived from a scenario's `name`: the name is free text, the folder must stay
//! under `out/` (a name of `../../x` or `/etc` must not write elsewhere).

use std::path::{Path, PathBuf};

/// Longest folder name derived from a scenario name \[bytes\]: well under the 255 bytes most file
/// systems allow for one path component.
pub const MAX_COMPONENT_LEN: usize = 100;

/// `name` as one safe path component: letters, digits, `-`, `_` and `.` kept, everything else
/// (separators, `..`, spaces, control characters) replaced by `_`, no leading dot, at most
/// [`MAX_COMPONENT_LEN`] bytes, never empty.
pub fn sanitize_component(name: &str) -> String {
    let mapped: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') { c } else { '_' })
        .take(MAX_COMPONENT_LEN)
        .collect();
    let trimmed = mapped.trim_start_matches('.');
    if trimmed.is_empty() { "run".into() } else { trimmed.into() }
}

/// The default output folder of a run of scenario `name`: `out/<sanitised name>`.
pub fn default_run_dir(name: &str) -> PathBuf {
    Path::new("out").join(sanitize_component(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_cannot_escape_out() {
        assert_eq!(default_run_dir("hammer"), Path::new("out/hammer"));
        assert_eq!(default_run_dir("../../escaped_by_name"), Path::new("out/_.._escaped_by_name"));
        assert_eq!(default_run_dir("/etc/passwd"), Path::new("out/_etc_passwd"));
        assert_eq!(default_run_dir(".."), Path::new("out/run"));
        assert_eq!(default_run_dir("a b\u{0}c"), Path::new("out/a_b_c"));
        assert_eq!(sanitize_component(&"x".repeat(1000)).len(), MAX_COMPONENT_LEN);
        for p in [default_run_dir("../.."), default_run_dir("a/../../b"), default_run_dir("C:\\x")] {
            assert_eq!(p.components().count(), 2, "{}", p.display());
        }
    }
}
