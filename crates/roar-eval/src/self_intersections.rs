//! Self-intersecting faces, counted the way `SOURCES.md`'s `selfX` column (MeshLab)
//! counts them, plus the paper's ε-offset variant (supplementary §1.1).
//!
//! Rules, all on the mesh welded at bit-identical positions ([`crate::weld_bit_identical`]):
//! - faces sharing a welded vertex or edge are *adjacent*; an adjacent pair intersects only when
//!   the two closed triangles meet beyond the shared vertex or edge (exact rules of
//!   `roar_mesh::spatial::faces_intersect`; duplicate faces always intersect);
//! - non-adjacent faces that merely touch (a corner on the other face, a shared position along an
//!   edge) intersect, as in MeshLab;
//! - a triangle with a repeated welded vertex is degenerate and counted only as such (never
//!   intersecting nor intersected).

use glam::DVec3;
use roar_mesh::spatial::{faces_intersect, intersecting_pairs};
use serde::Serialize;

use crate::fidelity::bbox_diagonal;

/// How the ε-offset re-test is done: a face whose intersections vanish once every vertex
/// moves by ε along its normal does not count (supplementary §1.1).
#[derive(Debug, Clone, PartialEq)]
pub struct SelfIntersectionOptions {
    /// The offset ε along each vertex normal, as a fraction of the bounding-box diagonal of the
    /// referenced vertices. Default 1e-5; the paper does not give ε.
    pub offset_over_diagonal: f64,
}

impl Default for SelfIntersectionOptions {
    fn default() -> Self {
        Self {
            offset_over_diagonal: 1e-5,
        }
    }
}

/// Self-intersecting faces of one mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SelfIntersectionStats {
    /// Faces (of the welded mesh, non-degenerate ones only) that intersect at least one other
    /// face beyond what adjacency forces; touching and exact duplicates count (MeshLab's rule,
    /// the `selfX` of `SOURCES.md`, except that MeshLab ignores every pair sharing a vertex).
    pub faces: usize,
    /// `faces` divided by the face count as stored (0 for an empty mesh).
    pub fraction: f64,
    /// The paper's figure: of `faces`, those that still intersect after every welded vertex moves
    /// by ε along its unit area-weighted vertex normal. Each pair found intersecting is re-tested
    /// with the offset positions (same adjacency rules); a face is kept when at least one of its
    /// pairs still intersects, and discounted ("trivially resolvable") when none does. Pairs
    /// that did not intersect before the offset are not tested, so `faces_eps_discounted ≤
    /// faces`. Its fraction of the face count is the paper's self-intersection percentage.
    pub faces_eps_discounted: usize,
    /// The ε used, in model units.
    pub offset: f64,
}

/// Unit area-weighted vertex normals (`roar_mesh::spatial`), along which the ε offset moves.
pub use roar_mesh::spatial::area_weighted_vertex_normals;

/// Counts self-intersecting faces of `(positions, triangles)` **as given**: callers weld first
/// (see the module rules; [`crate::evaluate`] does). Indices must be in range and coordinates
/// finite (see [`crate::validate_soup`]). Deterministic.
pub fn self_intersections(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &SelfIntersectionOptions,
) -> SelfIntersectionStats {
    let pairs = intersecting_pairs(positions, triangles);
    let offset = options.offset_over_diagonal * bbox_diagonal(positions, triangles);

    let mut hit = vec![false; triangles.len()];
    for &(i, j) in &pairs {
        hit[i as usize] = true;
        hit[j as usize] = true;
    }
    let faces = hit.iter().filter(|&&h| h).count();

    let normals = area_weighted_vertex_normals(positions, triangles);
    let moved: Vec<DVec3> = positions
        .iter()
        .zip(&normals)
        .map(|(&p, &n)| p + offset * n)
        .collect();
    let mut still = vec![false; triangles.len()];
    for &(i, j) in &pairs {
        let (ti, tj) = (triangles[i as usize], triangles[j as usize]);
        if faces_intersect(&moved, ti, tj) {
            still[i as usize] = true;
            still[j as usize] = true;
        }
    }
    let faces_eps_discounted = still.iter().filter(|&&h| h).count();

    SelfIntersectionStats {
        faces,
        fraction: if triangles.is_empty() {
            0.0
        } else {
            faces as f64 / triangles.len() as f64
        },
        faces_eps_discounted,
        offset,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit squares (two triangles each) in the planes z = 0 and z = `z`, the upper one
    /// shifted by `shift` in x.
    fn two_sheets(z: f64, shift: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        let mut t = Vec::new();
        for (k, (zz, dx)) in [(0.0, 0.0), (z, shift)].into_iter().enumerate() {
            let b = 4 * k as u32;
            p.extend([
                DVec3::new(dx, 0.0, zz),
                DVec3::new(dx + 1.0, 0.0, zz),
                DVec3::new(dx + 1.0, 1.0, zz),
                DVec3::new(dx, 1.0, zz),
            ]);
            t.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
        }
        (p, t)
    }

    #[test]
    fn crossing_triangles_intersect_and_survive_the_offset() {
        // Two triangles piercing each other deeply: the ε offset cannot separate them.
        let p = vec![
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.5, 2.0, 0.0),
            DVec3::new(5.0, 5.0, 5.0),
            DVec3::new(6.0, 5.0, 5.0),
            DVec3::new(5.0, 6.0, 5.0),
        ];
        let t = [[0, 1, 2], [3, 4, 5], [6, 7, 8]];
        let s = self_intersections(&p, &t, &SelfIntersectionOptions::default());
        assert_eq!(s.faces, 2);
        assert_eq!(s.faces_eps_discounted, 2);
        assert!((s.fraction - 2.0 / 3.0).abs() < 1e-15);
        let diag = (DVec3::new(6.0, 6.0, 5.0) - DVec3::new(-1.0, -1.0, -1.0)).length();
        assert!((s.offset - 1e-5 * diag).abs() < 1e-15);
    }

    #[test]
    fn coplanar_overlapping_sheets_with_the_same_normal_stay_intersecting() {
        // Coplanar, overlapping, both facing +z: the offset moves both the same way.
        let (p, t) = two_sheets(0.0, 0.5);
        let s = self_intersections(&p, &t, &SelfIntersectionOptions::default());
        assert_eq!(s.faces, 4);
        assert_eq!(s.faces_eps_discounted, 4);
    }

    #[test]
    fn touching_opposed_sheets_are_discounted_by_the_offset() {
        // The lower sheet faces down (-z), the upper one up (+z), and they overlap exactly in a
        // plane: a zero-thickness contact that moving each sheet along its own normal resolves.
        let (p, mut t) = two_sheets(0.0, 0.5);
        for f in &mut t[..2] {
            f.swap(1, 2);
        }
        let s = self_intersections(&p, &t, &SelfIntersectionOptions::default());
        assert_eq!(s.faces, 4, "exact overlap counts");
        assert_eq!(s.faces_eps_discounted, 0, "the offset separates them");
        // With a zero offset, nothing is discounted.
        let none = SelfIntersectionOptions {
            offset_over_diagonal: 0.0,
        };
        assert_eq!(self_intersections(&p, &t, &none).faces_eps_discounted, 4);
    }

    #[test]
    fn parallel_sheets_apart_do_not_intersect() {
        let (p, t) = two_sheets(0.1, 0.5);
        let s = self_intersections(&p, &t, &SelfIntersectionOptions::default());
        assert_eq!(s.faces, 0);
        assert_eq!(s.faces_eps_discounted, 0);
    }

    #[test]
    fn degenerate_faces_are_not_counted_and_empty_is_zero() {
        let (p, mut t) = two_sheets(0.0, 0.5);
        // Keep the lower sheet and add a repeated-index face whose segment lies on it.
        t.truncate(2);
        t.push([0, 0, 5]);
        let s = self_intersections(&p, &t, &SelfIntersectionOptions::default());
        assert_eq!(s.faces, 0);
        let e = self_intersections(&p, &[], &SelfIntersectionOptions::default());
        assert_eq!((e.faces, e.fraction), (0, 0.0));
    }

    #[test]
    fn vertex_normals_are_area_weighted() {
        // A big face facing +z and a small one facing +x share vertex 0.
        let p = vec![
            DVec3::ZERO,
            DVec3::X * 10.0,
            DVec3::Y * 10.0,
            DVec3::Y,
            DVec3::Z,
        ];
        let t = [[0, 1, 2], [0, 3, 4]];
        let n = area_weighted_vertex_normals(&p, &t);
        // Cross products: (0, 0, 100) and (1, 0, 0).
        let want = DVec3::new(1.0, 0.0, 100.0).normalize();
        assert!((n[0] - want).length() < 1e-15);
        assert_eq!(n[1], DVec3::Z);
        assert_eq!(n[3], DVec3::X);
    }
}
