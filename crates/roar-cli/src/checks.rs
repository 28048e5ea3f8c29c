//! Checks on what a user names besides the mesh, made before any work: the files a command reads
//! and writes are distinct (canonical paths, hard links and symbolic links included) and every
//! output can be written. And the one-line form of an error chain.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// What a path names on disk, for telling whether two paths are one file.
#[derive(Debug, PartialEq, Eq)]
enum Identity {
    /// An existing file: its device and inode (hard links and symbolic links share them).
    Inode(u64, u64),
    /// A file not there yet: its canonical folder joined with its name.
    Missing(PathBuf),
    /// Nothing we can resolve (its folder is missing too); `check_writable` reports it.
    Unknown,
}

fn identity(path: &Path) -> Identity {
    if let Ok(meta) = std::fs::metadata(path) {
        return Identity::Inode(meta.dev(), meta.ino());
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match (std::fs::canonicalize(folder), path.file_name()) {
        (Ok(folder), Some(name)) => Identity::Missing(folder.join(name)),
        _ => Identity::Unknown,
    }
}

/// Refuses, before any work, a command whose `inputs` and `outputs` (each a flag or argument name
/// and its path) name one file twice, or whose outputs cannot be written
/// (`roar_io::check_writable`: a missing folder, a folder or device as output, a dangling link,
/// a folder where no file can be created). So a run never ends by overwriting its own input,
/// or by failing to write after all the work.
pub fn check_paths(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> anyhow::Result<()> {
    let all: Vec<(&str, &Path, Identity)> = inputs
        .iter()
        .chain(outputs)
        .map(|&(role, path)| (role, path, identity(path)))
        .collect();
    for (i, (role_a, a, id_a)) in all.iter().enumerate() {
        for (role_b, b, id_b) in &all[i + 1..] {
            if *id_a != Identity::Unknown && id_a == id_b {
                anyhow::bail!(
                    "{role_a} {} and {role_b} {} name the same file; refusing to overwrite it",
                    a.display(),
                    b.display()
                );
            }
        }
    }
    for (_, path) in outputs {
        roar_io::check_writable(path)?;
    }
    Ok(())
}

/// An error and its causes on one line, each cause once: a cause whose text the line already
/// holds (an OS error a wrapper printed, too) is not repeated.
pub fn one_line(error: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in error.chain() {
        let text = cause.to_string().replace('\n', " ");
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hard_links_symbolic_links_and_spellings_are_one_file() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.obj");
        std::fs::write(&a, b"x").unwrap();
        let hard = dir.path().join("hard.obj");
        std::fs::hard_link(&a, &hard).unwrap();
        let soft = dir.path().join("soft.obj");
        std::os::unix::fs::symlink(&a, &soft).unwrap();
        let dotted = dir.path().join(".").join("a.obj");
        for same in [&a, &hard, &soft, &dotted] {
            let err = check_paths(&[("INPUT", &a)], &[("-o", same)]).unwrap_err();
            assert!(err.to_string().contains("name the same file"), "{err}");
        }
        let new = dir.path().join("new.obj");
        let err = check_paths(&[("INPUT", &a)], &[("-o", &new), ("--report", &new)]).unwrap_err();
        assert!(err.to_string().contains("name the same file"), "{err}");
        check_paths(&[("INPUT", &a)], &[("-o", &new)]).unwrap();
    }

    #[test]
    fn one_line_names_each_cause_once() {
        let os = std::io::Error::from_raw_os_error(21);
        let error = anyhow::Error::new(roar_io::IoError::Os {
            path: "out.obj".into(),
            source: os,
        });
        assert_eq!(one_line(&error), "out.obj: Is a directory (os error 21)");
        let error = anyhow::anyhow!("inner").context("outer");
        assert_eq!(one_line(&error), "outer: inner");
    }
}
