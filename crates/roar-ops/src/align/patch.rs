//! One scan's patch ([`ScanPatch`]): the triangles the alignment moves.

use glam::DVec3;

/// One scan's patch in its own frame.
#[derive(Debug, Clone, Copy)]
pub struct ScanPatch<'a> {
    /// Vertices in the scan's frame.
    pub positions: &'a [DVec3],
    /// Triangles (indices into `positions`), oriented toward the scanner.
    pub triangles: &'a [[u32; 3]],
}
