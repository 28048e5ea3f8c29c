//! The outward offset before the finish's QEMs: every vertex moves a fixed distance along its
//! normal, as far as it can without making faces intersect.

use glam::DVec3;
use roar_mesh::Mesh;
use roar_mesh::spatial::{Aabb, vertex_normals};

use crate::untangle::{LimiterOptions, limit_steps};

/// Moves every vertex `relative × diagonal` outward along its normal, each move shortened or
/// cancelled where it would make faces intersect; returns how many vertices moved the whole way.
///
/// Why: the optimization pulls the two sides of a thin part (and of an open surface, which the
/// init wraps from both sides) onto the same sheet, closer than any chord the final QEM makes,
/// so its self-intersection veto refuses nearly every collapse there and the decimation eats
/// the part from its rim instead. Offset apart, the two sides decimate like any other surface;
/// the polish then moves the vertices back onto the target.
pub fn offset_outward(mesh: &mut Mesh, relative: f64) -> usize {
    // Compact, the mesh's vertex ids are the indices of `to_triangles`.
    mesh.compact();
    let (positions, triangles) = mesh.to_triangles();
    let diagonal = Aabb::from_points(positions.iter().copied()).map_or(0.0, |b| b.diagonal());
    let distance = relative * diagonal;
    let normals = vertex_normals(&positions, &triangles);
    let mut moved: Vec<DVec3> = positions
        .iter()
        .zip(&normals)
        .map(|(&p, &n)| p + distance * n)
        .collect();
    let limited = limit_steps(
        &positions,
        &mut moved,
        &triangles,
        &LimiterOptions::default(),
    );
    mesh.positions_mut().copy_from_slice(&moved);
    positions.len() - limited.shortened - limited.cancelled
}
