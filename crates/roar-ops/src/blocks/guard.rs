//! An exact guard against self-intersections for blocks that change a mesh one local operation
//! at a time (edge collapses, edge flips).
//!
//! The loop's promise is an intersection-free mesh at every checkpoint, but the Face Collapse
//! block, its flips and the budget collapses of the Face Split block only look at local
//! geometry: a collapse on a thin part can push the new fan through the opposite wall. The guard
//! answers "would this operation make a face intersect another one?" exactly, before the block
//! applies it, so the block can skip it (`rejected["intersection"]`).
//!
//! How: a [`TriangleBvh`] over the faces as they were when the guard was made finds the
//! neighbours of the new faces. Faces an applied operation removed or reshaped are *changed*
//! (the caller reports them with [`IntersectionGuard::mark_around`] /
//! [`IntersectionGuard::mark`]); their BVH entries are ignored, and they are instead tested
//! from a short list with their current corners. Every test is
//! [`roar_mesh::spatial::faces_intersect_filtered`], exact behind certified filters.

use crate::blocks::block::BlockStats;
use glam::DVec3;
use roar_mesh::spatial::faces_intersect_filtered;
use roar_mesh::spatial::{Aabb, TriangleBvh};
use roar_mesh::{EdgeId, FaceId, HalfedgeId, Mesh, VertexId};

/// See the module docs. Made from an intersection-free mesh, and kept in step with it through
/// `mark*` after every operation the caller applies.
pub struct IntersectionGuard {
    bvh: TriangleBvh,
    /// BVH triangle index → face.
    faces: Vec<FaceId>,
    /// Per face slot: removed or reshaped since the guard was made.
    changed: Vec<bool>,
    /// The changed faces, each once.
    changed_list: Vec<FaceId>,
    /// Scratch: the faces an operation removes or reshapes, and the new corners.
    replaced: Vec<FaceId>,
    new_faces: Vec<([u32; 3], Aabb)>,
}

impl IntersectionGuard {
    /// A guard for `mesh` as it is now. Cost: one BVH build over its faces.
    pub fn new(mesh: &Mesh) -> Self {
        let faces: Vec<FaceId> = mesh.faces().collect();
        let triangles: Vec<[u32; 3]> = faces
            .iter()
            .map(|&f| mesh.face_vertices(f).map(|v| v.raw()))
            .collect();
        IntersectionGuard {
            bvh: TriangleBvh::build(mesh.positions(), &triangles),
            faces,
            changed: vec![false; mesh.face_capacity()],
            changed_list: Vec::new(),
            replaced: Vec::new(),
            new_faces: Vec::new(),
        }
    }

    /// Records that `f` was removed or reshaped (or is new) since the guard was made.
    pub fn mark(&mut self, f: FaceId) {
        if self.changed.len() <= f.index() {
            self.changed.resize(f.index() + 1, false);
        }
        if !self.changed[f.index()] {
            self.changed[f.index()] = true;
            self.changed_list.push(f);
        }
    }

    /// Records that every face around `v` changed (call it on the survivor of a collapse, with
    /// [`Self::mark`] on the removed faces).
    pub fn mark_around(&mut self, mesh: &Mesh, v: VertexId) {
        for f in mesh.faces_around(v) {
            self.mark(f);
        }
    }

    /// Whether collapsing `h` (its tail merged into its head, the head moved to `p`) would make
    /// one of the resulting faces intersect another face. The mesh is unchanged on return
    /// (the two endpoints are moved to `p` for the test and moved back).
    pub fn collapse_intersects(&mut self, mesh: &mut Mesh, h: HalfedgeId, p: DVec3) -> bool {
        let (a, b) = (mesh.tail(h), mesh.head(h));
        self.replaced.clear();
        self.replaced.extend(mesh.faces_around(a));
        self.replaced.extend(mesh.faces_around(b));
        let gone = [mesh.face(h), mesh.face(h.twin())];
        self.new_faces.clear();
        for &f in &self.replaced {
            if !gone.contains(&f) {
                let corners = mesh
                    .face_vertices(f)
                    .map(|v| if v == a { b.raw() } else { v.raw() });
                self.new_faces.push((corners, Aabb::EMPTY));
            }
        }
        let (pa, pb) = (mesh.position(a), mesh.position(b));
        mesh.set_position(a, p);
        mesh.set_position(b, p);
        let hit = self.new_faces_intersect(mesh);
        mesh.set_position(a, pa);
        mesh.set_position(b, pb);
        hit
    }

    /// Whether flipping `e` (faces `(a, b, c)`, `(b, a, d)` become `(a, d, c)`, `(b, c, d)`)
    /// would make one of the two new faces intersect another face.
    pub fn flip_intersects(&mut self, mesh: &Mesh, e: EdgeId) -> bool {
        let h = e.halfedge();
        let (a, b) = (mesh.tail(h), mesh.head(h));
        let (c, d) = (mesh.opposite_vertex(h), mesh.opposite_vertex(h.twin()));
        self.replaced.clear();
        self.replaced.extend([mesh.face(h), mesh.face(h.twin())]);
        self.new_faces.clear();
        self.new_faces
            .push(([a, d, c].map(|v| v.raw()), Aabb::EMPTY));
        self.new_faces
            .push(([b, c, d].map(|v| v.raw()), Aabb::EMPTY));
        self.new_faces_intersect(mesh)
    }

    /// Whether a face of `self.new_faces` (corners in current positions) intersects another new
    /// face or a live face outside `self.replaced`.
    fn new_faces_intersect(&mut self, mesh: &Mesh) -> bool {
        let positions = mesh.positions();
        let mut all = Aabb::EMPTY;
        for (corners, bx) in &mut self.new_faces {
            *bx = Aabb::from_triangle(corners.map(|v| positions[v as usize]));
            all = all.union(bx);
        }
        let replaced = &self.replaced;
        let new_faces = &self.new_faces;
        let against = |other: [u32; 3], other_box: &Aabb| {
            new_faces.iter().any(|(tri, bx)| {
                bx.overlaps(other_box) && faces_intersect_filtered(positions, *tri, other)
            })
        };
        for (i, (tri, bx)) in new_faces.iter().enumerate() {
            for (other, other_box) in &new_faces[i + 1..] {
                if bx.overlaps(other_box) && faces_intersect_filtered(positions, *tri, *other) {
                    return true;
                }
            }
        }
        for &f in &self.changed_list {
            if mesh.is_face_alive(f) && !replaced.contains(&f) {
                let corners = mesh.face_vertices(f);
                let other_box = Aabb::from_triangle(corners.map(|v| positions[v.index()]));
                if other_box.overlaps(&all) && against(corners.map(|v| v.raw()), &other_box) {
                    return true;
                }
            }
        }
        let mut hit = false;
        self.bvh.faces_in_aabb(&all, |i| {
            let f = self.faces[i as usize];
            if hit || self.changed[f.index()] || replaced.contains(&f) {
                return;
            }
            let corners = mesh.face_vertices(f);
            let other_box = Aabb::from_triangle(corners.map(|v| positions[v.index()]));
            hit = against(corners.map(|v| v.raw()), &other_box);
        });
        hit
    }
}

/// Flips `e` unless the flip is topologically illegal ([`Mesh::can_flip`],
/// `rejected["topology"]`) or a new face would intersect another face
/// (`rejected["intersection"]`), keeping `guard` in step. The guard is built at the first flip
/// that gets this far, so callers with nothing to flip pay nothing for it. Returns whether `e`
/// was flipped. The sliver and data-dependent flips of a finished mesh share this last step.
pub fn flip_if_clean(
    mesh: &mut Mesh,
    e: EdgeId,
    guard: &mut Option<IntersectionGuard>,
    stats: &mut BlockStats,
) -> bool {
    if mesh.can_flip(e).is_err() {
        stats.reject("topology", 1);
        return false;
    }
    let guard = guard.get_or_insert_with(|| IntersectionGuard::new(mesh));
    if guard.flip_intersects(mesh, e) {
        stats.reject("intersection", 1);
        return false;
    }
    let h = e.halfedge();
    guard.mark(mesh.face(h));
    guard.mark(mesh.face(h.twin()));
    mesh.flip(e).expect("flip passed can_flip (invariant)");
    true
}

/// Collapses `h` (its tail merged into its head, which keeps its position) unless the
/// collapse is topologically illegal ([`Mesh::can_collapse`], `rejected["topology"]`) or a
/// reshaped face would intersect another face (`rejected["intersection"]`), keeping `guard` in
/// step (built at the first collapse that gets this far). Returns whether `h` was collapsed.
/// The degenerate and fin collapses of a finished mesh share this last step.
pub fn collapse_if_clean(
    mesh: &mut Mesh,
    h: HalfedgeId,
    guard: &mut Option<IntersectionGuard>,
    stats: &mut BlockStats,
) -> bool {
    if mesh.can_collapse(h).is_err() {
        stats.reject("topology", 1);
        return false;
    }
    let guard = guard.get_or_insert_with(|| IntersectionGuard::new(mesh));
    let head = mesh.position(mesh.head(h));
    if guard.collapse_intersects(mesh, h, head) {
        stats.reject("intersection", 1);
        return false;
    }
    let done = mesh
        .collapse(h)
        .expect("collapse passed can_collapse (invariant)");
    for f in done.removed_faces {
        guard.mark(f);
    }
    guard.mark_around(mesh, done.survivor);
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::count_intersecting_faces;

    fn intersects(mesh: &Mesh) -> bool {
        count_intersecting_faces(mesh) > 0
    }

    /// A sphere with a second, smaller sphere just inside one of its vertices: collapsing an
    /// edge at that vertex toward the centre cuts through the inner sphere.
    fn sphere_in_sphere() -> Mesh {
        let (mut positions, mut triangles) = icosphere(2).to_triangles();
        let n = positions.len() as u32;
        let inner: Vec<DVec3> = positions
            .iter()
            .map(|p| *p * 0.2 + DVec3::new(0.0, 0.0, 0.6))
            .collect();
        triangles.extend(
            triangles
                .clone()
                .iter()
                .map(|t| t.map(|v| v + n))
                .collect::<Vec<_>>(),
        );
        positions.extend(inner);
        Mesh::from_triangles(positions, &triangles).unwrap()
    }

    /// Every collapse of an outer-sphere edge to a random-ish point: the guard's answer equals
    /// the all-pairs check of the collapsed mesh.
    #[test]
    fn collapse_answers_match_the_all_pairs_check() {
        let base = sphere_in_sphere();
        assert!(!intersects(&base));
        let (mut agreed, mut hits) = (0, 0);
        for e in base.edges().step_by(3) {
            for t in [0.0, 0.5, 1.0, 3.0] {
                let mut mesh = base.clone();
                let h = e.halfedge();
                if mesh.can_collapse(h).is_err() {
                    continue;
                }
                let (pa, pb) = (mesh.position(mesh.tail(h)), mesh.position(mesh.head(h)));
                // t = 3 overshoots toward the centre, so some placements cut the inner sphere.
                let p = if t == 3.0 { pb * 0.3 } else { pa.lerp(pb, t) };
                let mut guard = IntersectionGuard::new(&mesh);
                let predicted = guard.collapse_intersects(&mut mesh, h, p);
                let survivor = mesh.collapse(h).unwrap().survivor;
                mesh.set_position(survivor, p);
                assert_eq!(predicted, intersects(&mesh), "edge {e:?}, t {t}");
                agreed += 1;
                hits += predicted as usize;
            }
        }
        assert!(agreed > 100 && hits > 0, "agreed {agreed}, hits {hits}");
    }

    /// After a sequence of applied collapses (marked), the guard still sees the changed faces:
    /// its answers match the all-pairs check of each result.
    #[test]
    fn marked_collapses_keep_the_guard_exact() {
        let mut mesh = sphere_in_sphere();
        let mut guard = IntersectionGuard::new(&mesh);
        let (mut applied, mut vetoed) = (0, 0);
        let edges: Vec<EdgeId> = mesh.edges().collect();
        for e in edges {
            if !mesh.is_edge_alive(e) || mesh.can_collapse(e.halfedge()).is_err() {
                continue;
            }
            let h = e.halfedge();
            let p = mesh.position(mesh.head(h)) * 0.45;
            let predicted = guard.collapse_intersects(&mut mesh, h, p);
            let mut trial = mesh.clone();
            let s = trial.collapse(h).unwrap().survivor;
            trial.set_position(s, p);
            assert_eq!(predicted, intersects(&trial), "edge {e:?}");
            if predicted {
                vetoed += 1;
                continue;
            }
            let c = mesh.collapse(h).unwrap();
            mesh.set_position(c.survivor, p);
            for f in c.removed_faces {
                guard.mark(f);
            }
            guard.mark_around(&mesh, c.survivor);
            applied += 1;
            if applied == 40 {
                break;
            }
        }
        assert!(
            applied == 40 && vetoed > 0,
            "applied {applied}, vetoed {vetoed}"
        );
    }

    #[test]
    fn flip_answers_match_the_all_pairs_check() {
        let base = sphere_in_sphere();
        let (mut tested, mut hits) = (0, 0);
        for e in base.edges() {
            let mut mesh = base.clone();
            // Pull one opposite corner far inward so that some flips dive into the inner sphere.
            let c = mesh.opposite_vertex(e.halfedge());
            mesh.set_position(c, mesh.position(c) * 0.55);
            if intersects(&mesh) || mesh.can_flip(e).is_err() {
                continue;
            }
            let mut guard = IntersectionGuard::new(&mesh);
            let predicted = guard.flip_intersects(&mesh, e);
            mesh.flip(e).unwrap();
            assert_eq!(predicted, intersects(&mesh), "edge {e:?}");
            tested += 1;
            hits += predicted as usize;
        }
        assert!(tested > 50 && hits > 0, "tested {tested}, hits {hits}");
    }
}
