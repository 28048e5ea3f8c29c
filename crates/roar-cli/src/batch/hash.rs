//! Fingerprints for resuming: the 64-bit FNV-1a hash of a file's bytes (or of a folder's files,
//! names included), written as 16 hex digits.
//!
//! FNV-1a detects changes, not tampering: it is what `roar batch` needs to tell whether an
//! input, a configuration or the `roar` executable differs from the one that made an output.

use std::io::Read;
use std::path::Path;

use anyhow::Context;

/// A streaming 64-bit FNV-1a hash.
#[derive(Debug, Clone)]
pub struct Fnv64(u64);

impl Default for Fnv64 {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv64 {
    /// Feeds `bytes` to the hash.
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }

    /// The hash as 16 lowercase hex digits.
    pub fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }
}

/// The hash of `bytes` as 16 hex digits.
pub fn hash_bytes(bytes: &[u8]) -> String {
    let mut h = Fnv64::default();
    h.update(bytes);
    h.hex()
}

/// The hash of a file's bytes, or of every file under a folder (sorted by relative path, each
/// path hashed with its bytes, so renaming a file changes it too).
pub fn hash_path(path: &Path) -> anyhow::Result<String> {
    let mut h = Fnv64::default();
    let meta =
        std::fs::metadata(path).with_context(|| format!("cannot read {}", path.display()))?;
    if meta.is_dir() {
        let mut files = Vec::new();
        collect_files(path, path, &mut files)?;
        files.sort();
        for relative in files {
            h.update(relative.as_bytes());
            h.update(&[0]);
            feed_file(&mut h, &path.join(&relative))?;
        }
    } else {
        feed_file(&mut h, path)?;
    }
    Ok(h.hex())
}

fn feed_file(h: &mut Fnv64, path: &Path) -> anyhow::Result<()> {
    let mut file =
        std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut buffer = vec![0u8; 1 << 16];
    loop {
        let n = file
            .read(&mut buffer)
            .with_context(|| format!("cannot read {}", path.display()))?;
        if n == 0 {
            return Ok(());
        }
        h.update(&buffer[..n]);
    }
}

fn collect_files(root: &Path, folder: &Path, out: &mut Vec<String>) -> anyhow::Result<()> {
    let entries =
        std::fs::read_dir(folder).with_context(|| format!("cannot read {}", folder.display()))?;
    for entry in entries {
        let path = entry
            .with_context(|| format!("cannot read {}", folder.display()))?
            .path();
        if path.is_dir() {
            collect_files(root, &path, out)?;
        } else {
            let relative = path.strip_prefix(root).unwrap_or(&path);
            out.push(relative.to_string_lossy().replace('\\', "/"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_the_published_test_vectors() {
        // From the FNV reference test suite (Fowler, Noll, Vo).
        assert_eq!(hash_bytes(b""), "cbf29ce484222325");
        assert_eq!(hash_bytes(b"a"), "af63dc4c8601ec8c");
        assert_eq!(hash_bytes(b"foobar"), "85944171f73967e8");
    }

    #[test]
    fn a_folder_hash_sees_contents_and_names() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        std::fs::write(dir.path().join("sub/a.ply"), b"one").unwrap();
        let first = hash_path(dir.path()).unwrap();
        std::fs::write(dir.path().join("sub/a.ply"), b"two").unwrap();
        let second = hash_path(dir.path()).unwrap();
        std::fs::rename(dir.path().join("sub/a.ply"), dir.path().join("sub/b.ply")).unwrap();
        let third = hash_path(dir.path()).unwrap();
        assert_ne!(first, second);
        assert_ne!(second, third);
        assert!(hash_path(&dir.path().join("missing")).is_err());
    }
}
