//! Files written whole or not at all: summaries, scenarios, results, frames and videos.

use std::path::{Path, PathBuf};

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
