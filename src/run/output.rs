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

/// Writes `bytes` to a temporary file beside `path`, syncs it and renames it over `path`: a
/// failure (a full disk) leaves the previous file as it was, never half a new one. On error the
/// temporary file is removed; the error names the file that failed. A path that exists and is not
/// a regular file (`/dev/null`, a pipe) is written in place: renaming over it would replace it.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), (PathBuf, std::io::Error)> {
    use std::io::Write;
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return std::fs::write(path, bytes).map_err(|e| (path.to_path_buf(), e));
    }
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".tmp");
    let tmp = path.with_file_name(name);
    let write = || -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    };
    if let Err(e) = write() {
        let _ = std::fs::remove_file(&tmp);
        return Err((tmp, e));
    }
    std::fs::rename(&tmp, path).map_err(|e| (path.to_path_buf(), e))
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

    #[test]
    fn atomic_writes_replace_whole_files_and_leave_devices_alone() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("summary.json");
        std::fs::write(&f, "old").unwrap();
        write_atomically(&f, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&f).unwrap(), "new");
        assert!(!dir.path().join("summary.json.tmp").exists());
        // Into a folder that does not exist: an error naming the temporary file, nothing left.
        let err = write_atomically(&dir.path().join("no/such"), b"x").unwrap_err();
        assert!(err.0.ends_with("such.tmp"), "{}", err.0.display());
        if Path::new("/dev/null").exists() {
            write_atomically(Path::new("/dev/null"), b"x").unwrap();
            assert!(!std::fs::metadata("/dev/null").unwrap().is_file(), "/dev/null replaced");
        }
        if Path::new("/dev/full").exists() {
            assert!(write_atomically(Path::new("/dev/full"), b"x").is_err());
        }
    }
}
