//! Face budgets a user may ask for, known before any work: a closed triangle mesh has an even face
//! count (3F = 2E), and each closed piece needs at least the faces of the smallest triangulation
//! of its genus (4 for a sphere, 14 for a torus: `roar_ops::decimate::minimum_faces_for_genus`).
//! Every operator keeps the pieces; the genera too, unless handles may be removed (the finish's
//! `roar_ops::finish::genus`), which brings the smallest budget down to a tetrahedron per piece.

use roar_ops::decimate::minimum_faces_for_genus;

/// The smallest face count a closed mesh with pieces of these genera can be decimated to: with
/// `keep_topology`, the sum of each piece's minimum (`2(V − 2 + 2g)` with Heawood's vertex
/// bound); otherwise handles may be removed and each piece needs a tetrahedron's 4 faces
/// (`roar_ops::finish::genus::min_reachable_budget`). 0 pieces → 0.
pub fn smallest_budget(genera: &[usize], keep_topology: bool) -> usize {
    if keep_topology {
        genera.iter().copied().map(minimum_faces_for_genus).sum()
    } else {
        roar_ops::finish::genus::min_reachable_budget(genera.len())
    }
}

/// Faces a merged piece is given on average: when an input has more separate parts than
/// `faces / FACES_PER_PIECE`, the init merges nearby ones until the pieces fit
/// ([`pieces_to_aim_for`]), so each can keep a recognisable shape rather than be a tetrahedron.
pub const FACES_PER_PIECE: usize = 40;

/// The most pieces the init aims for at a budget of `faces` faces (at least 1): more are merged
/// by proximity (`roar_ops::init::InitOptions::target_pieces`).
pub fn pieces_to_aim_for(faces: usize) -> usize {
    (faces / FACES_PER_PIECE).max(1)
}

/// The most pieces any mesh of `faces` faces can have when handles may be removed (a
/// tetrahedron each; at least 1): the init drops the smallest pieces beyond it, so a budget that
/// is even and at least 4 is never refused for the pieces of the init
/// (`roar_ops::init::InitOptions::max_pieces`).
pub fn most_pieces(faces: usize) -> usize {
    (faces / roar_ops::finish::genus::min_reachable_budget(1)).max(1)
}

/// A face budget no mesh of the pieces at hand can have. Its message names only budgets that
/// work: the nearest even counts at or above `minimum`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{what} {faces} {}; {}", self.why(), self.advice())]
pub struct BudgetError {
    /// How the user gave the budget (`--faces`, `faces =`), for the message.
    pub what: &'static str,
    /// The budget asked for.
    pub faces: usize,
    /// The smallest budget that works (even, at least 4).
    pub minimum: usize,
}

impl BudgetError {
    fn why(&self) -> String {
        if self.faces < self.minimum {
            format!(
                "is below the smallest reachable budget, {} faces",
                self.minimum
            )
        } else {
            "is odd, but a closed triangle mesh always has an even face count".to_string()
        }
    }

    fn advice(&self) -> String {
        let below = self.faces - self.faces % 2;
        if below >= self.minimum && below != self.faces {
            format!("use {below} or {}", below + 2)
        } else {
            format!("use {}", self.minimum.max(self.faces + self.faces % 2))
        }
    }
}

/// Checks `faces` against the smallest budget `minimum` (raised to 4) before any work: it must be
/// even and at least `minimum`.
pub fn check_budget(what: &'static str, faces: usize, minimum: usize) -> Result<(), BudgetError> {
    let minimum = minimum.max(4);
    if faces >= minimum && faces.is_multiple_of(2) {
        return Ok(());
    }
    Err(BudgetError {
        what,
        faces,
        minimum,
    })
}

/// Refuses a face budget no closed mesh can have, up front: odd (3F = 2E) or below the 4 faces
/// of a tetrahedron.
pub fn check_even_budget(faces: usize) -> Result<(), BudgetError> {
    check_budget("--faces", faces, 4)
}

/// Bytes a reconstruction is expected to need at its peak, from the sizes that drive it: the
/// working budget `W` (the loop's mesh, its BVH and optimizer state, the renders' per-face
/// buffers), the input's faces (the cleaned target and its BVH), the target renders' pixels,
/// the point cloud (and its k-d tree) and a fixed part. A rough linear model: the fixed and
/// per-pixel parts match the measured peaks of short runs (docs/reliability.md, "Memory"); the
/// per-face part is a deliberately high guess. It is meant to tell a budget that fits from one
/// that cannot, not to predict a figure.
pub fn estimated_peak_bytes(sizes: &RunSizes) -> u64 {
    FIXED_BYTES
        + BYTES_PER_WORKING_FACE * sizes.working_faces as u64
        + BYTES_PER_INPUT_FACE * sizes.input_faces as u64
        + BYTES_PER_PIXEL * sizes.render_pixels
        + BYTES_PER_SAMPLE * sizes.cloud_samples as u64
}

/// The sizes [`estimated_peak_bytes`] reads (the caller takes them from its config and input).
#[derive(Debug, Clone, Copy)]
pub struct RunSizes {
    /// The working budget W.
    pub working_faces: usize,
    /// Faces of the input.
    pub input_faces: usize,
    /// Pixels of all target renders together.
    pub render_pixels: u64,
    /// Point cloud samples.
    pub cloud_samples: usize,
}

/// Memory the kernel says is available (`MemAvailable` in `/proc/meminfo`), if it says.
pub fn available_memory_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

const FIXED_BYTES: u64 = 128 << 20;
const BYTES_PER_WORKING_FACE: u64 = 2048;
const BYTES_PER_INPUT_FACE: u64 = 512;
const BYTES_PER_PIXEL: u64 = 40;
/// The cloud and its k-d tree, in each of the run's two k-NN projectors (the planar loss's and
/// the blocks'), each also holding a copy of the points and normals in the tree's padded leaf
/// slots (up to 2 × 48 bytes per point).
const BYTES_PER_SAMPLE: u64 = 448;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smallest_budgets_of_spheres_tori_and_several_pieces() {
        assert_eq!(smallest_budget(&[0], true), 4);
        assert_eq!(smallest_budget(&[1], true), 14);
        assert_eq!(smallest_budget(&[1], false), 4);
        assert_eq!(smallest_budget(&[2, 0], false), 8);
        assert_eq!(smallest_budget(&[0, 0], true), 8);
        assert_eq!(smallest_budget(&[0, 1], true), 18);
        assert_eq!(smallest_budget(&[], true), 0);
    }

    #[test]
    fn advice_names_only_budgets_that_work() {
        for (faces, minimum, advice) in [
            (1, 4, "use 4"),
            (3, 4, "use 4"),
            (0, 4, "use 4"),
            (5, 4, "use 4 or 6"),
            (4, 8, "use 8"),
            (9, 8, "use 8 or 10"),
            (13, 14, "use 14"),
        ] {
            let message = check_budget("--faces", faces, minimum)
                .unwrap_err()
                .to_string();
            assert!(message.ends_with(advice), "{faces}: {message}");
            let suggested: Vec<usize> = message
                .rsplit("use ")
                .next()
                .unwrap()
                .split(" or ")
                .map(|n| n.parse().unwrap())
                .collect();
            for s in suggested {
                check_budget("--faces", s, minimum).unwrap();
            }
        }
        check_budget("--faces", 4, 4).unwrap();
        check_budget("--faces", 5000, 8).unwrap();
    }
}
