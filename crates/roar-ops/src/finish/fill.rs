//! The fill to a face budget by edge splits: the finish's way back up to N after the untangle
//! block's and the degenerate collapses' removals. Splits move no geometry, so no
//! self-intersection can appear.

use roar_mesh::{EdgeId, Mesh};

use crate::geometry::{DEGENERATE_QUALITY, is_degenerate};
use roar_mesh::spatial::triangle_quality;

/// Splits edges at their midpoints until the mesh has `faces` faces (each split adds two),
/// longest first, skipping edges whose halving would leave a degenerate face
/// ([`bisects_well`]): halving a needle's long edge leaves two needles and halving a flat
/// cap's edge can make a flatter one, which would undo the degenerate collapses this fill
/// follows. When no edge qualifies the longest is split anyway, so the fill always ends. The
/// geometry does not change, so no intersection can appear. Returns the split count.
pub fn fill_to_budget(mesh: &mut Mesh, faces: usize) -> usize {
    let mut splits = 0;
    while mesh.n_faces() < faces {
        let mut edges: Vec<(f64, EdgeId)> = mesh
            .edges()
            .filter(|&e| bisects_well(mesh, e))
            .map(|e| (mesh.edge_length(e), e))
            .collect();
        if edges.is_empty() {
            edges = mesh.edges().map(|e| (mesh.edge_length(e), e)).collect();
        }
        // Longest first; ties by id keep it deterministic.
        edges.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let wanted = (faces - mesh.n_faces()) / 2;
        for &(_, e) in edges.iter().take(wanted.max(1)) {
            if mesh.n_faces() >= faces {
                break;
            }
            mesh.split_edge(e, 0.5);
            splits += 1;
        }
    }
    mesh.compact();
    splits
}

/// Whether halving `e` leaves no degenerate face ([`DEGENERATE_QUALITY`]): neither face of `e`
/// is degenerate, nor is any of the four faces the split would make (see [`fill_to_budget`]).
pub fn bisects_well(mesh: &Mesh, e: EdgeId) -> bool {
    let h = mesh.edge_halfedge(e);
    [h, h.twin()].into_iter().all(|h| {
        let (a, b) = (mesh.position(mesh.tail(h)), mesh.position(mesh.head(h)));
        let c = mesh.position(mesh.head(mesh.next(h)));
        let m = 0.5 * (a + b);
        [[a, b, c], [a, m, c], [m, b, c]]
            .into_iter()
            .all(|t| !is_degenerate(triangle_quality(t), DEGENERATE_QUALITY))
    })
}
