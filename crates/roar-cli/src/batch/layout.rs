//! Every file a batch writes, and when an item counts as done.
//!
//! Per item and budget, under `OUTDIR/<id>/`:
//! - `<budget>.<ext>`: the mesh, moved there from `<budget>.partial.<ext>` once the child
//!   process succeeded;
//! - `<budget>.json`: the [`ItemRecord`], written atomically after the mesh: its presence is what
//!   marks the item done;
//! - `<budget>.failure.json`: the [`FailureRecord`] of the last attempt, when it failed;
//! - `<budget>.log`: the child's stderr of the last attempt.
//!
//! `OUTDIR/manifest.json` is the [`Plan`] (every item and budget, written by shard 0), and the
//! failures of a run are appended, one JSON line each, to `OUTDIR/failures.jsonl` (or
//! `failures-I-of-K.jsonl` for shard I of K, so concurrent shards never write one file).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// The whole batch as the manifest defines it, for `roar batch-report`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Plan {
    /// The manifest file.
    pub manifest: String,
    /// Extension of the meshes.
    pub format: String,
    /// Every item in manifest order.
    pub items: Vec<PlanItem>,
}

/// One item of the [`Plan`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PlanItem {
    /// The item's id.
    pub id: String,
    /// Its input path.
    pub input: String,
    /// Its budgets.
    pub budgets: Vec<usize>,
    /// Its manifest labels, which `roar batch-report --by` groups done, failed and missing
    /// items by (absent in plans of batches before labels).
    #[serde(default)]
    pub labels: BTreeMap<String, String>,
}

/// What `OUTDIR/<id>/<budget>.json` holds: the fingerprints that decide a resume, and the
/// child's `roar reconstruct` report.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ItemRecord {
    /// The item's id.
    pub id: String,
    /// Its budget.
    pub budget: usize,
    /// The input path.
    pub input: String,
    /// Hash of the input's bytes.
    pub input_hash: String,
    /// Hash of the effective configuration (as `--print-config` writes it).
    pub config_hash: String,
    /// Hash of the `roar` executable that made the output.
    pub build: String,
    /// Wall-clock seconds of the child process.
    pub seconds: f64,
    /// The item's manifest labels when it ran, so the record describes its item on its own
    /// (absent in records of batches before labels).
    #[serde(default)]
    pub labels: BTreeMap<String, String>,
    /// The `roar reconstruct` JSON report.
    pub reconstruct: serde_json::Value,
}

/// One failed attempt, as `failures.jsonl` and `<budget>.failure.json` record it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FailureRecord {
    /// The item's id.
    pub id: String,
    /// Its budget.
    pub budget: usize,
    /// Why, in one line.
    pub reason: String,
    /// Seconds the attempt ran.
    pub seconds: f64,
}

/// The files of one item at one budget.
#[derive(Debug, Clone)]
pub struct ItemFiles {
    /// `OUTDIR/<id>`.
    pub folder: PathBuf,
    /// The finished mesh.
    pub mesh: PathBuf,
    /// The finished record.
    pub record: PathBuf,
    /// The failure of the last attempt.
    pub failure: PathBuf,
    /// The child's stderr.
    pub log: PathBuf,
    /// Where the child writes its mesh.
    pub partial_mesh: PathBuf,
    /// Where the child writes its report.
    pub partial_report: PathBuf,
    budget: usize,
}

impl ItemFiles {
    /// The files of item `id` at `budget` under `outdir`, meshes with extension `format`.
    pub fn new(outdir: &Path, id: &str, budget: usize, format: &str) -> Self {
        let folder = outdir.join(id);
        let at = |name: String| folder.join(name);
        Self {
            mesh: at(format!("{budget}.{format}")),
            record: at(format!("{budget}.json")),
            failure: at(format!("{budget}.failure.json")),
            log: at(format!("{budget}.log")),
            partial_mesh: at(format!("{budget}.partial.{format}")),
            partial_report: at(format!("{budget}.partial.json")),
            folder,
            budget,
        }
    }

    /// Whether this budget is done with these fingerprints: mesh and record present, the record
    /// readable and naming the same input, config and build, and no leftover of an interrupted
    /// attempt (a partial output or an atomic writer's temporary file) beside them.
    pub fn is_done(&self, input_hash: &str, config_hash: &str, build: &str) -> bool {
        if !self.mesh.is_file() || !self.leftovers().is_empty() {
            return false;
        }
        match self.read_record() {
            Some(r) => {
                r.input_hash == input_hash && r.config_hash == config_hash && r.build == build
            }
            None => false,
        }
    }

    /// The finished record, if present and readable.
    pub fn read_record(&self) -> Option<ItemRecord> {
        let text = std::fs::read_to_string(&self.record).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// The last failure, if present and readable.
    pub fn read_failure(&self) -> Option<FailureRecord> {
        let text = std::fs::read_to_string(&self.failure).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// Partial outputs and atomic-write temporaries of this budget (`.<budget>.….tmp`).
    pub fn leftovers(&self) -> Vec<PathBuf> {
        let mut found = vec![self.partial_mesh.clone(), self.partial_report.clone()];
        found.retain(|p| p.exists());
        let temp_prefix = format!(".{}.", self.budget);
        if let Ok(entries) = std::fs::read_dir(&self.folder) {
            for entry in entries.flatten() {
                let name = entry.file_name().to_string_lossy().into_owned();
                if name.starts_with(&temp_prefix) && name.ends_with(".tmp") {
                    found.push(entry.path());
                }
            }
        }
        found
    }

    /// Removes everything of an earlier attempt before a new one, so a crash in the middle of
    /// it can never leave a stale record beside a new mesh.
    pub fn clear(&self) -> std::io::Result<()> {
        for path in self.leftovers() {
            remove_if_present(&path)?;
        }
        for path in [&self.record, &self.failure, &self.mesh] {
            remove_if_present(path)?;
        }
        Ok(())
    }
}

/// Removes a file, a missing one being no error.
pub fn remove_if_present(path: &Path) -> std::io::Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// The failures log of shard `index` of `count`.
pub fn failures_log(outdir: &Path, index: usize, count: usize) -> PathBuf {
    if count == 1 {
        outdir.join("failures.jsonl")
    } else {
        outdir.join(format!("failures-{index}-of-{count}.jsonl"))
    }
}

/// The plan file of a batch.
pub fn plan_path(outdir: &Path) -> PathBuf {
    outdir.join("manifest.json")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(files: &ItemFiles, build: &str) {
        let r = ItemRecord {
            id: "a".into(),
            budget: 100,
            input: "in.obj".into(),
            input_hash: "i".into(),
            config_hash: "c".into(),
            build: build.into(),
            seconds: 1.0,
            labels: BTreeMap::new(),
            reconstruct: serde_json::Value::Null,
        };
        std::fs::write(&files.record, serde_json::to_string(&r).unwrap()).unwrap();
    }

    #[test]
    fn done_needs_mesh_matching_record_and_no_leftovers() {
        let dir = tempfile::tempdir().unwrap();
        let files = ItemFiles::new(dir.path(), "a", 100, "obj");
        std::fs::create_dir_all(&files.folder).unwrap();
        assert!(!files.is_done("i", "c", "b"));
        record(&files, "b");
        assert!(!files.is_done("i", "c", "b"), "no mesh yet");
        std::fs::write(&files.mesh, "o\n").unwrap();
        assert!(files.is_done("i", "c", "b"));
        assert!(!files.is_done("j", "c", "b"));
        assert!(!files.is_done("i", "d", "b"));
        assert!(!files.is_done("i", "c", "other build"));
        let temp = files.folder.join(".100.obj.x1y2.tmp");
        std::fs::write(&temp, "").unwrap();
        assert!(!files.is_done("i", "c", "b"), "a stale temp file");
        // Another budget's temp file is not this budget's business.
        std::fs::rename(&temp, files.folder.join(".1000.obj.x.tmp")).unwrap();
        assert!(files.is_done("i", "c", "b"));
        std::fs::write(&files.record, "{ truncated").unwrap();
        assert!(!files.is_done("i", "c", "b"));
        std::fs::write(&files.partial_mesh, "").unwrap();
        files.clear().unwrap();
        assert!(!files.mesh.exists() && !files.record.exists() && !files.partial_mesh.exists());
    }
}
