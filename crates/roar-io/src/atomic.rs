//! Atomic file writes: all of the new content or none of it.

use std::io::{BufWriter, Write};
use std::path::Path;

use crate::error::IoError;

/// Writes a file atomically: `write` fills a temporary file in the same folder as `path`, which
/// is flushed, synced to disk and then renamed over `path`.
///
/// Promise: on success `path` holds exactly what `write` wrote; on any error (from `write`, the
/// disk or the rename) `path` is untouched (an old file stays as it was, a missing one stays
/// missing) and the temporary file is removed. Same folder means same file system, so the
/// rename is atomic.
pub fn atomic_write(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), IoError> {
    let os = |source: std::io::Error| IoError::Os {
        path: path.to_path_buf(),
        source,
    };
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let prefix = format!(".{}.", name.as_deref().unwrap_or("roar"));
    // Dropping `temp` on any early return deletes the temporary file.
    let temp = tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(".tmp")
        .tempfile_in(folder)
        .map_err(os)?;
    let mut out = BufWriter::new(temp);
    write(&mut out).map_err(os)?;
    let temp = out.into_inner().map_err(|e| os(e.into_error()))?;
    temp.as_file().sync_all().map_err(os)?;
    temp.persist(path).map_err(|e| os(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_content_and_leaves_no_temporary_files() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        atomic_write(&path, |w| w.write_all(b"hello")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"hello");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn failed_write_keeps_old_file_and_removes_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        std::fs::write(&path, b"old").unwrap();
        let err = atomic_write(&path, |w| {
            w.write_all(b"partial new content")?;
            Err(std::io::Error::other("disk on fire"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("a.txt"), "{err}");
        assert!(err.to_string().contains("disk on fire"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn missing_folder_is_an_error_naming_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/folder/a.txt");
        let err = atomic_write(&path, |w| w.write_all(b"x")).unwrap_err();
        assert!(err.to_string().contains("a.txt"), "{err}");
    }
}
