//! Edge collapses inside [`super::untangle`]: a crossing that involves a sliver (or that moving
//! vertices has not fixed for several rounds) is often cheaper to remove than to move away.
//!
//! A collapse is applied only when [`Mesh::can_collapse`] allows it (link condition: the genus
//! and the piece count are kept) and a simulation on the current buffers shows that it strictly
//! lowers the number of intersecting pairs around it and flips no remaining face.

use crate::geometry::{DEGENERATE_QUALITY, is_degenerate};
use glam::DVec3;
use roar_mesh::spatial::faces_intersect_filtered as faces_cross;
use roar_mesh::spatial::{Aabb, TriangleBvh, triangle_quality};
use roar_mesh::{FaceId, HalfedgeId, Mesh, VertexId};

/// The working buffers of [`super::untangle`]: slot positions, live triangles (slot indices),
/// their face ids, the slot of each face id, and the one-ring of every vertex slot.
pub(super) struct Buffers {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub face_ids: Vec<FaceId>,
    /// `index_of[face id slot]` = index into `triangles`, `u32::MAX` for dead faces.
    pub index_of: Vec<u32>,
    pub adjacency: Vec<Vec<u32>>,
}

impl Buffers {
    /// Buffers of `mesh` at its current positions.
    pub fn from_mesh(mesh: &Mesh) -> Buffers {
        let positions = mesh.positions().to_vec();
        let face_ids: Vec<FaceId> = mesh.faces().collect();
        let triangles = face_ids
            .iter()
            .map(|&f| mesh.face_vertices(f).map(VertexId::raw))
            .collect();
        let mut index_of = vec![u32::MAX; mesh.face_capacity()];
        for (i, f) in face_ids.iter().enumerate() {
            index_of[f.index()] = i as u32;
        }
        let mut adjacency = vec![Vec::new(); mesh.vertex_capacity()];
        for v in mesh.vertices() {
            adjacency[v.index()] = mesh.neighbors(v).map(VertexId::raw).collect();
        }
        Buffers {
            positions,
            triangles,
            face_ids,
            index_of,
            adjacency,
        }
    }
}

/// Intersecting pairs `(x, y)` with `x` in `faces` (sorted slot indices of `triangles`) and `y`
/// any other face not excluded by `skip`; a pair inside `faces` is counted once.
fn count_crossings(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    bvh: &TriangleBvh,
    faces: &[[u32; 3]],
    skip: impl Fn(u32) -> bool,
) -> usize {
    let mut count = 0;
    for (k, &tf) in faces.iter().enumerate() {
        let b = Aabb::from_triangle(tf.map(|i| positions[i as usize]));
        bvh.faces_in_aabb(&b, |g| {
            if !skip(g) && faces_cross(positions, tf, triangles[g as usize]) {
                count += 1;
            }
        });
        for &tg in &faces[k + 1..] {
            if faces_cross(positions, tf, tg) {
                count += 1;
            }
        }
    }
    count
}

/// Tries to collapse one edge of face `f`, shortest edge first, with the survivor at the edge
/// midpoint or at either end. Applies the first candidate that passes the checks (see the
/// module docs) to `mesh` and returns true; `buffers` and `bvh` must describe `mesh` (positions
/// included) and are stale afterwards.
pub(super) fn try_collapse_face(
    mesh: &mut Mesh,
    buffers: &Buffers,
    bvh: &TriangleBvh,
    f: FaceId,
) -> bool {
    if !mesh.is_face_alive(f) {
        return false;
    }
    let mut halfedges = mesh.face_halfedges(f);
    let length = |h: HalfedgeId| {
        let (a, b) = (mesh.tail(h), mesh.head(h));
        mesh.position(a).distance(mesh.position(b))
    };
    halfedges.sort_by(|&x, &y| length(x).total_cmp(&length(y)));
    for h in halfedges {
        let (a, b) = (mesh.tail(h), mesh.head(h));
        let (pa, pb) = (mesh.position(a), mesh.position(b));
        // (half-edge whose head survives, survivor position)
        let options = [(h, 0.5 * (pa + pb)), (h, pb), (h.twin(), pa)];
        for (g, target) in options {
            if mesh.can_collapse(g).is_err() {
                continue;
            }
            if collapse_helps(mesh, buffers, bvh, g, target) {
                let survivor = mesh.head(g);
                if mesh.collapse(g).is_ok() {
                    mesh.set_position(survivor, target);
                    return true;
                }
            }
        }
    }
    false
}

/// Simulates collapsing `h: a → b` with `b` placed at `target`: no remaining face around `a` or
/// `b` flips or degenerates, and the intersecting pairs involving the faces around `a` and `b`
/// strictly decrease.
fn collapse_helps(
    mesh: &Mesh,
    buffers: &Buffers,
    bvh: &TriangleBvh,
    h: HalfedgeId,
    target: DVec3,
) -> bool {
    let (a, b) = (mesh.tail(h), mesh.head(h));
    let removed = [mesh.face(h), mesh.face(h.twin())];
    let mut ring: Vec<FaceId> = mesh.faces_around(a).chain(mesh.faces_around(b)).collect();
    ring.sort_unstable();
    ring.dedup();
    let slot = |f: FaceId| buffers.index_of[f.index()];
    if ring.iter().any(|&f| slot(f) == u32::MAX) {
        return false;
    }
    let mut ring_slots: Vec<u32> = ring.iter().map(|&f| slot(f)).collect();
    ring_slots.sort_unstable();
    let in_ring = |g: u32| ring_slots.binary_search(&g).is_ok();
    let old_faces: Vec<[u32; 3]> = ring
        .iter()
        .map(|&f| buffers.triangles[slot(f) as usize])
        .collect();
    let (ra, rb) = (a.raw(), b.raw());
    let mut positions = buffers.positions.clone();
    let mut new_faces = Vec::with_capacity(ring.len());
    for (f, &t) in ring.iter().zip(&old_faces) {
        if !removed.contains(f) {
            new_faces.push(t.map(|i| if i == ra { rb } else { i }));
        }
    }
    // Remaining faces keep their orientation and stay non-degenerate.
    let old_normal = |t: [u32; 3]| {
        let [p, q, r] = t.map(|i| positions[i as usize]);
        (q - p).cross(r - p)
    };
    let olds: Vec<DVec3> = ring
        .iter()
        .zip(&old_faces)
        .filter(|(f, _)| !removed.contains(f))
        .map(|(_, &t)| old_normal(t))
        .collect();
    positions[b.index()] = target;
    for (t, n_old) in new_faces.iter().zip(&olds) {
        let [p, q, r] = t.map(|i| positions[i as usize]);
        let n_new = (q - p).cross(r - p);
        if n_new.dot(*n_old) <= 0.0
            || is_degenerate(triangle_quality([p, q, r]), DEGENERATE_QUALITY)
        {
            return false;
        }
    }
    let before = count_crossings(
        &buffers.positions,
        &buffers.triangles,
        bvh,
        &old_faces,
        in_ring,
    );
    if before == 0 {
        return false;
    }
    // Faces outside the ring do not touch `a` or `b`, so their boxes in `bvh` are current.
    let after = count_crossings(&positions, &buffers.triangles, bvh, &new_faces, in_ring);
    after < before
}
