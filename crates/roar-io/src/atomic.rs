//! Atomic file writes: all of the new content or none of it.
//!
//! The temporary file is created in the destination's folder (same file system, so the final
//! rename is atomic) and registered while it exists, so that a program stopped by a signal can
//! remove it ([`remove_temporary_files`]).

use std::fs::Permissions;
use std::io::{BufWriter, Write};
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::IoError;

/// Temporary files of the writes in progress, for [`remove_temporary_files`].
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Removes the temporary files of every [`atomic_write`] still in progress and returns how many
/// it removed. Meant for a signal handler's thread just before the process exits (SIGINT,
/// SIGTERM): the destinations stay untouched, and no `.NAME.XXXXXX.tmp` is left behind.
pub fn remove_temporary_files() -> usize {
    temporary_files()
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}

/// The temporary files of the writes in progress.
fn temporary_files() -> Vec<PathBuf> {
    match IN_FLIGHT.lock() {
        Ok(paths) => paths.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    }
}

/// Registers a temporary path for the lifetime of the guard.
struct InFlight(PathBuf);

impl InFlight {
    fn new(path: &Path) -> Self {
        if let Ok(mut paths) = IN_FLIGHT.lock() {
            paths.push(path.to_path_buf());
        }
        InFlight(path.to_path_buf())
    }
}

impl Drop for InFlight {
    fn drop(&mut self) {
        if let Ok(mut paths) = IN_FLIGHT.lock()
            && let Some(i) = paths.iter().position(|p| *p == self.0)
        {
            paths.swap_remove(i);
        }
    }
}

/// The file an [`atomic_write`] to `path` replaces: `path` itself, or the existing file a
/// symbolic link at `path` points to (the write goes through the link, which stays a link).
///
/// Errors: a dangling link, or a destination that exists but is not a regular file (a folder,
/// a device such as `/dev/full`, a FIFO): replacing those by renaming would destroy them.
pub fn write_destination(path: &Path) -> Result<PathBuf, IoError> {
    let refuse = |message: String| IoError::InvalidInput {
        path: path.to_path_buf(),
        message,
    };
    let target = match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => std::fs::canonicalize(path).map_err(|_| {
            refuse("is a symbolic link to nothing (dangling); refusing to write".into())
        })?,
        Ok(_) => path.to_path_buf(),
        Err(_) => return Ok(path.to_path_buf()),
    };
    match std::fs::metadata(&target) {
        Ok(meta) if meta.is_dir() => Err(refuse("is a folder, not a file".into())),
        Ok(meta) if !meta.is_file() => Err(refuse(
            "is not a regular file (a device, FIFO or socket); refusing to replace it".into(),
        )),
        _ => Ok(target),
    }
}

/// Checks, before any work, that [`atomic_write`] to `path` can succeed as far as the file system
/// can tell: the destination is acceptable ([`write_destination`]), its folder exists and a
/// temporary file can be created there (it is removed at once). A full disk can still fail the
/// write itself, which then leaves nothing behind.
pub fn check_writable(path: &Path) -> Result<(), IoError> {
    let target = write_destination(path)?;
    let folder = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let refuse = |message: String| IoError::InvalidInput {
        path: path.to_path_buf(),
        message,
    };
    match std::fs::metadata(folder) {
        Ok(meta) if meta.is_dir() => {}
        Ok(_) => return Err(refuse(format!("{} is not a folder", folder.display()))),
        Err(_) => {
            return Err(refuse(format!(
                "folder {} does not exist",
                folder.display()
            )));
        }
    }
    tempfile::Builder::new()
        .prefix(".roar-probe.")
        .tempfile_in(folder)
        .map(drop)
        .map_err(|e| {
            refuse(format!(
                "cannot create files in {}: {}",
                folder.display(),
                plain(e)
            ))
        })
}

/// An OS error without the decorations some crates add (tempfile appends the temporary file's
/// name): the message names the user's path once.
fn plain(error: std::io::Error) -> std::io::Error {
    if error.raw_os_error().is_some() {
        return error;
    }
    // tempfile's wrapper reads "<os error> at path \"<temporary file>\"".
    let text = error.to_string();
    match text.split_once(" at path \"") {
        Some((message, _)) => std::io::Error::new(error.kind(), message.to_string()),
        None => error,
    }
}

/// Writes a file atomically: `write` fills a temporary file in the same folder as `path`, which
/// is flushed, synced to disk and then renamed over `path`.
///
/// Promise: on success `path` holds exactly what `write` wrote; on any error (from `write`, the
/// disk or the rename) `path` is untouched (an old file stays as it was, a missing one stays
/// missing) and the temporary file is removed. Same folder means same file system, so the
/// rename is atomic. Permissions: a new file gets `0666` minus the process's umask, as with any
/// tool; a replaced file keeps its mode. A symbolic link is written through (see
/// [`write_destination`]); errors name `path`, never the temporary file.
pub fn atomic_write(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), IoError> {
    stage(path, write)?.commit()
}

/// Writes several files all or nothing as far as the file system allows: every file's content is
/// written to its temporary file and synced first (a full disk or any other failure then leaves
/// every destination untouched); only then are they renamed into place, in order. Each file as
/// in [`atomic_write`].
pub fn atomic_write_all(files: Vec<(&Path, FileContent<'_>)>) -> Result<(), IoError> {
    let mut staged = Vec::with_capacity(files.len());
    for (path, write) in files {
        staged.push(stage(path, write)?);
    }
    staged.into_iter().try_for_each(Staged::commit)
}

/// What [`atomic_write_all`] writes into one file.
pub type FileContent<'a> = Box<dyn FnOnce(&mut dyn Write) -> std::io::Result<()> + 'a>;

/// A temporary file holding a destination's complete new content, synced, not yet renamed.
struct Staged {
    path: PathBuf,
    target: PathBuf,
    temp: tempfile::NamedTempFile,
    _registered: InFlight,
}

impl Staged {
    /// Renames the temporary file over the destination.
    fn commit(self) -> Result<(), IoError> {
        let Staged {
            path,
            target,
            temp,
            _registered,
        } = self;
        temp.persist(&target).map_err(|e| IoError::Os {
            path,
            source: plain(e.error),
        })?;
        Ok(())
    }
}

/// Writes `write`'s content to a temporary file beside `path`'s destination and syncs it.
fn stage(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<Staged, IoError> {
    let os = |source: std::io::Error| IoError::Os {
        path: path.to_path_buf(),
        source: plain(source),
    };
    let target = write_destination(path)?;
    let folder = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let existing_mode = std::fs::metadata(&target)
        .ok()
        .map(|meta| meta.permissions().mode() & 0o7777);
    let name = target.file_name().map(|n| n.to_string_lossy().into_owned());
    let prefix = format!(".{}.", name.as_deref().unwrap_or("roar"));
    // Dropping `temp` on any early return deletes the temporary file.
    let temp = tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(".tmp")
        .permissions(Permissions::from_mode(0o666))
        .tempfile_in(folder)
        .map_err(os)?;
    let registered = InFlight::new(temp.path());
    if let Some(mode) = existing_mode {
        temp.as_file()
            .set_permissions(Permissions::from_mode(mode))
            .map_err(os)?;
    }
    let mut out = BufWriter::new(temp);
    write(&mut out).map_err(os)?;
    let temp = out.into_inner().map_err(|e| os(e.into_error()))?;
    temp.as_file().sync_all().map_err(os)?;
    Ok(Staged {
        path: path.to_path_buf(),
        target,
        temp,
        _registered: registered,
    })
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

#[cfg(test)]
mod destination_tests {
    use super::*;

    fn mode(path: &Path) -> u32 {
        std::fs::metadata(path).unwrap().permissions().mode() & 0o7777
    }

    #[test]
    fn replacing_a_file_keeps_its_mode() {
        let dir = tempfile::tempdir().unwrap();
        for wanted in [0o644, 0o600, 0o664] {
            let path = dir.path().join(format!("m{wanted:o}.txt"));
            std::fs::write(&path, b"old").unwrap();
            std::fs::set_permissions(&path, Permissions::from_mode(wanted)).unwrap();
            atomic_write(&path, |w| w.write_all(b"new")).unwrap();
            assert_eq!(std::fs::read(&path).unwrap(), b"new");
            assert_eq!(mode(&path), wanted, "{}", path.display());
        }
    }

    #[test]
    fn writes_through_a_symbolic_link_and_keeps_the_link() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.txt");
        let link = dir.path().join("link.txt");
        std::fs::write(&real, b"old").unwrap();
        std::os::unix::fs::symlink(&real, &link).unwrap();
        atomic_write(&link, |w| w.write_all(b"new")).unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
    }

    #[test]
    fn refuses_dangling_links_folders_and_devices() {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("dangling.txt");
        std::os::unix::fs::symlink(dir.path().join("nothing"), &link).unwrap();
        let err = atomic_write(&link, |w| w.write_all(b"x")).unwrap_err();
        assert!(err.to_string().contains("dangling"), "{err}");
        let err = atomic_write(dir.path(), |w| w.write_all(b"x")).unwrap_err();
        assert!(err.to_string().contains("is a folder"), "{err}");
        let err = atomic_write(Path::new("/dev/null"), |w| w.write_all(b"x")).unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
        assert!(Path::new("/dev/null").exists());
    }

    #[test]
    fn errors_name_the_path_once_and_never_the_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing/a.txt");
        let message = atomic_write(&path, |w| w.write_all(b"x"))
            .unwrap_err()
            .to_string();
        assert!(!message.contains(".a.txt."), "{message}");
        assert_eq!(message.matches("a.txt").count(), 1, "{message}");
    }

    #[test]
    fn temporary_files_are_registered_while_writing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        let mut registered = Vec::new();
        atomic_write(&path, |w| {
            // The write is in progress: a signal now would remove this temporary file.
            registered = temporary_files()
                .into_iter()
                .filter(|p| p.starts_with(dir.path()))
                .collect();
            w.write_all(b"x")
        })
        .unwrap();
        assert_eq!(registered.len(), 1, "{registered:?}");
        assert!(!registered[0].exists());
        assert!(!temporary_files().contains(&registered[0]));
    }

    #[test]
    fn a_failing_file_of_several_leaves_every_destination_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.obj"), dir.path().join("b.json"));
        std::fs::write(&a, b"old").unwrap();
        let err = atomic_write_all(vec![
            (
                a.as_path(),
                Box::new(|w: &mut dyn Write| w.write_all(b"new")),
            ),
            (
                b.as_path(),
                Box::new(|_: &mut dyn Write| Err(std::io::Error::from_raw_os_error(28))),
            ),
        ])
        .unwrap_err();
        assert!(err.to_string().contains("b.json"), "{err}");
        assert_eq!(std::fs::read(&a).unwrap(), b"old");
        assert_eq!(files(dir.path()), ["a.obj"]);
        atomic_write_all(vec![
            (
                a.as_path(),
                Box::new(|w: &mut dyn Write| w.write_all(b"new")),
            ),
            (
                b.as_path(),
                Box::new(|w: &mut dyn Write| w.write_all(b"{}")),
            ),
        ])
        .unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"new");
        assert_eq!(files(dir.path()), ["a.obj", "b.json"]);
    }

    fn files(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn check_writable_finds_missing_folders_and_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        check_writable(&dir.path().join("a.obj")).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let err = check_writable(&dir.path().join("no/a.obj")).unwrap_err();
        assert!(err.to_string().contains("does not exist"), "{err}");
        let file = dir.path().join("f");
        std::fs::write(&file, b"").unwrap();
        let err = check_writable(&file.join("a.obj")).unwrap_err();
        assert!(err.to_string().contains("is not a folder"), "{err}");
        let err = check_writable(dir.path()).unwrap_err();
        assert!(err.to_string().contains("is a folder"), "{err}");
    }
}
