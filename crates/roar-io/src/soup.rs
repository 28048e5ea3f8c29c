//! [`TriangleSoup`]: the plain buffers every reader produces and every writer consumes.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use glam::DVec3;

/// A triangle soup: positions and index triples, with no promise about topology.
///
/// Anything goes: duplicated, unreferenced or coincident vertices, degenerate triangles (repeated
/// indices), non-manifold edges, inconsistent winding. Readers only promise what
/// [`TriangleSoup::validate`] checks: at least one triangle, finite coordinates, indices in range.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleSoup {
    /// Vertex positions, in file order (f64; STL's f32 values convert exactly).
    pub positions: Vec<DVec3>,
    /// Triangles as 0-based indices into `positions`, in file order; a polygon with `k` corners
    /// becomes `k − 2` triangles by ear clipping in its plane (a convex one: the fan
    /// `(c0, c1, c2), (c0, c2, c3), ...`).
    pub triangles: Vec<[u32; 3]>,
    /// How many faces of the input were polygons with more than 3 corners (0 for soups that were
    /// not read from a file).
    pub n_polygons: usize,
    /// How many of those polygons could not be triangulated cleanly (no plane, corners off their
    /// plane, a self-intersecting outline, a corner out of range, too many corners) and were
    /// fan-triangulated, at least in part.
    pub n_polygons_unclean: usize,
    /// How many faces of the input had fewer than 3 corners (OBJ `f 1 2`, an OFF or PLY face
    /// listing 2 indices, an ASCII STL loop of 2 vertices): they bound no surface, so they were
    /// skipped rather than refused.
    pub n_faces_skipped: usize,
}

/// Why a soup is not valid (see [`TriangleSoup::validate`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SoupDefect {
    /// The soup has no triangles.
    Empty,
    /// A coordinate of this vertex is NaN or infinite.
    NonFinite {
        /// The vertex.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The offending index.
        index: u32,
    },
}

impl std::fmt::Display for SoupDefect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SoupDefect::Empty => write!(f, "mesh has no triangles"),
            SoupDefect::NonFinite { vertex } => {
                write!(f, "vertex {vertex} has a NaN or infinite coordinate")
            }
            SoupDefect::IndexOutOfRange { triangle, index } => {
                write!(f, "triangle {triangle} refers to missing vertex {index}")
            }
        }
    }
}

impl TriangleSoup {
    /// A soup from positions and triangles (all counts 0). Nothing is checked; see
    /// [`TriangleSoup::validate`].
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            positions,
            triangles,
            n_polygons: 0,
            n_polygons_unclean: 0,
            n_faces_skipped: 0,
        }
    }

    /// Checks what every reader promises: at least one triangle, all coordinates finite and
    /// every index `< positions.len()`. Degenerate triangles (repeated indices) are valid.
    pub fn validate(&self) -> Result<(), SoupDefect> {
        if self.triangles.is_empty() {
            return Err(SoupDefect::Empty);
        }
        if let Some(vertex) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(SoupDefect::NonFinite { vertex });
        }
        let n = self.positions.len();
        for (triangle, t) in self.triangles.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= n) {
                return Err(SoupDefect::IndexOutOfRange { triangle, index });
            }
        }
        Ok(())
    }

    /// Welds vertices with identical positions into one, keeping the first occurrence's order.
    ///
    /// Positions are compared exactly (bit for bit), except that `-0.0` and `+0.0` count as the
    /// same coordinate (they are the same point). Returns the welded soup (triangles remapped,
    /// degenerate triangles kept, the counts copied) and the map old vertex → new vertex.
    /// Indices out of range are left as they are (validate first if that matters).
    pub fn welded(&self) -> (TriangleSoup, Vec<u32>) {
        let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(self.positions.len());
        let mut positions = Vec::new();
        let mut old_to_new = Vec::with_capacity(self.positions.len());
        for &p in &self.positions {
            // Adding +0.0 maps -0.0 to +0.0 and leaves every other value unchanged.
            let key = [
                (p.x + 0.0).to_bits(),
                (p.y + 0.0).to_bits(),
                (p.z + 0.0).to_bits(),
            ];
            let new = match first.entry(key) {
                Entry::Occupied(e) => *e.get(),
                Entry::Vacant(e) => {
                    let id = positions.len() as u32;
                    positions.push(p);
                    *e.insert(id)
                }
            };
            old_to_new.push(new);
        }
        let triangles = self
            .triangles
            .iter()
            .map(|t| t.map(|i| old_to_new.get(i as usize).copied().unwrap_or(i)))
            .collect();
        let soup = TriangleSoup {
            positions,
            triangles,
            n_polygons: self.n_polygons,
            n_polygons_unclean: self.n_polygons_unclean,
            n_faces_skipped: self.n_faces_skipped,
        };
        (soup, old_to_new)
    }
}

/// The writers' guard: a soup that fails [`TriangleSoup::validate`] would produce a file no
/// reader accepts (or make the writer index out of bounds), so it is refused with
/// [`std::io::ErrorKind::InvalidInput`] before anything is written.
pub(crate) fn ensure_writable(soup: &TriangleSoup) -> std::io::Result<()> {
    soup.validate().map_err(|defect| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("cannot write an invalid mesh: {defect}"),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad_with_duplicates() -> TriangleSoup {
        TriangleSoup::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(-0.0, 0.0, -0.0), // same point as vertex 0
                DVec3::new(1.0, 1.0, 0.0),   // same as vertex 2
                DVec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [3, 4, 5]],
        )
    }

    #[test]
    fn weld_merges_identical_positions_in_first_seen_order() {
        let (w, map) = quad_with_duplicates().welded();
        assert_eq!(map, vec![0, 1, 2, 0, 2, 3]);
        assert_eq!(w.positions.len(), 4);
        assert_eq!(w.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(w.positions[3], DVec3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn weld_keeps_nearby_but_different_positions_apart() {
        let a = 0.1_f64;
        let b = f64::from_bits(a.to_bits() + 1);
        let soup = TriangleSoup::new(
            vec![DVec3::splat(a), DVec3::splat(b), DVec3::ONE],
            vec![[0, 1, 2]],
        );
        assert_eq!(soup.welded().0.positions.len(), 3);
    }

    #[test]
    fn weld_keeps_degenerate_triangles() {
        let soup = TriangleSoup::new(vec![DVec3::ZERO, DVec3::ZERO, DVec3::X], vec![[0, 1, 2]]);
        let (w, _) = soup.welded();
        assert_eq!(w.triangles, vec![[0, 0, 1]]);
    }

    #[test]
    fn validate_reports_each_defect() {
        assert_eq!(TriangleSoup::default().validate(), Err(SoupDefect::Empty));
        let mut s = quad_with_duplicates();
        assert_eq!(s.validate(), Ok(()));
        s.triangles[1][2] = 6;
        assert_eq!(
            s.validate(),
            Err(SoupDefect::IndexOutOfRange {
                triangle: 1,
                index: 6
            })
        );
        s.triangles[1][2] = 5;
        s.positions[4].y = f64::NAN;
        assert_eq!(s.validate(), Err(SoupDefect::NonFinite { vertex: 4 }));
    }
}
