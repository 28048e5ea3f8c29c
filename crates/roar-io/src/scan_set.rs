//! Scan sets: the Stanford `.conf` file that lists range images and their poses.
//!
//! A `.conf` holds one `bmesh FILE tx ty tz qx qy qz qw` line per scan: the scan's file
//! (relative to the `.conf`'s folder) and the rigid transform from the scan's own frame into the
//! common frame, a translation and a unit quaternion with w last. A `camera` line (one viewing
//! camera for the whole set, not a scanner pose) and blank lines are skipped; anything else is an
//! error. [`ScanPose::to_common`] applies the transform in the reading that aligns the Stanford
//! scans (measured in `roar-ops`' test `scan_alignment`).

use std::path::{Path, PathBuf};

use glam::{DQuat, DVec3};

use crate::error::IoError;
use crate::range_grid::RangeGrid;
use crate::text::{lines, parse_f64, show, tokens};

/// One scan of a set: its file and the rigid transform from its frame into the common frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanPose {
    /// The scan's file (the `.conf`'s folder joined with the name given there).
    pub path: PathBuf,
    /// Translation `tx ty tz`.
    pub translation: DVec3,
    /// The quaternion `qx qy qz qw` as written, normalized.
    pub quaternion: DQuat,
}

impl ScanPose {
    /// The rotation into the common frame: the written quaternion with its scalar part negated,
    /// i.e. the inverse of the written rotation (the reading under which the Stanford scans
    /// meet; the written one leaves them centimetres apart).
    pub fn rotation(&self) -> DQuat {
        let q = self.quaternion;
        DQuat::from_xyzw(q.x, q.y, q.z, -q.w)
    }

    /// Maps a point of the scan's frame into the common frame: `R p + t`.
    pub fn to_common(&self, p: DVec3) -> DVec3 {
        self.rotation() * p + self.translation
    }
}

/// A scan set: the `.conf` it came from and its scans in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanSet {
    /// The `.conf` file.
    pub conf: PathBuf,
    /// The scans, in the order of their `bmesh` lines.
    pub scans: Vec<ScanPose>,
}

/// Whether `path` names a scan set: a `.conf` file, or a folder holding one.
pub fn is_scan_set(path: &Path) -> bool {
    path.is_dir()
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("conf"))
}

/// Reads a scan set from a `.conf` file, or from a folder holding exactly one `.conf`.
///
/// Errors (one line, naming the file and line): a folder with no or several `.conf` files, an
/// unreadable file, a malformed `bmesh` line (missing or non-finite numbers, a zero
/// quaternion), an unknown keyword, no `bmesh` line, or a listed scan file that does not exist.
pub fn read_scan_set(path: &Path) -> Result<ScanSet, IoError> {
    let conf = if path.is_dir() {
        find_conf(path)?
    } else {
        path.to_path_buf()
    };
    let bytes = std::fs::read(&conf).map_err(|source| IoError::Os {
        path: conf.clone(),
        source,
    })?;
    let name = conf.display().to_string();
    let folder = conf.parent().unwrap_or(Path::new(""));
    let mut scans = Vec::new();
    for (line_no, line) in lines(&bytes) {
        let toks: Vec<&[u8]> = tokens(line).collect();
        let err = |msg: String| IoError::at_line(&name, line_no, msg);
        match toks.as_slice() {
            [] | [b"camera", ..] => {}
            [b"bmesh", file, numbers @ ..] => {
                if numbers.len() != 7 {
                    return Err(err(format!(
                        "bmesh needs a file and 7 numbers (tx ty tz qx qy qz qw), found {}",
                        numbers.len()
                    )));
                }
                let mut v = [0.0; 7];
                for (slot, tok) in v.iter_mut().zip(numbers) {
                    *slot = parse_f64(tok)
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| err(format!("{:?} is not a finite number", show(tok))))?;
                }
                let quaternion = DQuat::from_xyzw(v[3], v[4], v[5], v[6]);
                let length = quaternion.length();
                if length <= 1e-9 {
                    return Err(err("the quaternion is zero".to_string()));
                }
                let file = String::from_utf8_lossy(file).into_owned();
                let scan = folder.join(&file);
                if !scan.is_file() {
                    return Err(err(format!(
                        "scan file {file:?} not found next to the .conf"
                    )));
                }
                scans.push(ScanPose {
                    path: scan,
                    translation: DVec3::new(v[0], v[1], v[2]),
                    quaternion: quaternion / length,
                });
            }
            [other, ..] => {
                return Err(err(format!(
                    "unknown keyword {:?} (expected bmesh or camera)",
                    show(other)
                )));
            }
        }
    }
    if scans.is_empty() {
        return Err(IoError::in_file(
            &name,
            "no 'bmesh' line: the set has no scans",
        ));
    }
    Ok(ScanSet { conf, scans })
}

/// The one `.conf` file in `folder`.
fn find_conf(folder: &Path) -> Result<PathBuf, IoError> {
    let os = |source| IoError::Os {
        path: folder.to_path_buf(),
        source,
    };
    let mut found = Vec::new();
    for entry in std::fs::read_dir(folder).map_err(os)? {
        let path = entry.map_err(os)?.path();
        if path.is_file() && is_scan_set(&path) {
            found.push(path);
        }
    }
    found.sort();
    match found.len() {
        1 => Ok(found.remove(0)),
        0 => Err(IoError::InvalidInput {
            path: folder.to_path_buf(),
            message: "folder holds no .conf scan set".to_string(),
        }),
        n => Err(IoError::InvalidInput {
            path: folder.to_path_buf(),
            message: format!("folder holds {n} .conf files; name one"),
        }),
    }
}

/// Reads a scan from a PLY file, a range image or points alone, and makes its patch with
/// `options` ([`crate::RangeGrid::patch`], [`crate::point_scan_patch`]). Errors: those of the
/// PLY reader, and a PLY file with faces (not a scan).
pub fn read_scan_patch_file(
    path: &Path,
    options: &crate::PatchOptions,
) -> Result<(crate::TriangleSoup, crate::PatchStats), IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    crate::ply::read_scan_patch(&bytes, &path.display().to_string(), options)
}

/// Reads a range image from a PLY file ([`crate::read_range_grid`] on its bytes).
pub fn read_range_grid_file(path: &Path) -> Result<RangeGrid, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    crate::read_range_grid(&bytes, &path.display().to_string())
}
