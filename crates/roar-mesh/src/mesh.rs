//! The [`Mesh`] type: storage, navigation, live-element iteration and per-element geometry.

use crate::handles::{EdgeId, FaceId, HalfedgeId, VertexId};
use crate::triangle::DEGENERATE_CROSS;
use glam::DVec3;

/// Raw-array sentinel for "no element"; never exposed by the public API.
pub(crate) const INVALID: u32 = u32::MAX;

/// A closed, oriented, 2-manifold triangle mesh in half-edge form.
///
/// Storage is struct-of-arrays indexed by handle (`he_*` by [`HalfedgeId`], `v_*` by
/// [`VertexId`], `f_*` by [`FaceId`], `e_alive` by [`EdgeId`]). Half-edges come in twin pairs
/// (`twin(h) = h ^ 1`), so there is no twin array; triangles make `prev = next ∘ next`, so there is
/// no prev array.
///
/// Deleted elements are tombstoned (their `alive` flag is cleared) and their slots are kept until
/// [`Mesh::compact`]; operators always **append** new elements and never reuse tombstoned slots,
/// so a caller's per-element arrays only ever grow between compactions.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// `he_next[h]`: the next half-edge counter-clockwise in `h`'s face.
    pub(crate) he_next: Vec<u32>,
    /// `he_head[h]`: the vertex `h` points to.
    pub(crate) he_head: Vec<u32>,
    /// `he_face[h]`: the face `h` belongs to (every half-edge has one: the mesh is closed).
    pub(crate) he_face: Vec<u32>,
    /// `v_halfedge[v]`: one half-edge leaving `v`.
    pub(crate) v_halfedge: Vec<u32>,
    /// `f_halfedge[f]`: one half-edge of `f`; `face_vertices(f)` starts at its tail.
    pub(crate) f_halfedge: Vec<u32>,
    /// Vertex positions; dead slots may hold anything.
    pub(crate) positions: Vec<DVec3>,
    pub(crate) v_alive: Vec<bool>,
    pub(crate) f_alive: Vec<bool>,
    pub(crate) e_alive: Vec<bool>,
    pub(crate) n_live_vertices: usize,
    pub(crate) n_live_faces: usize,
    pub(crate) n_live_edges: usize,
}

impl Mesh {
    // ----- navigation -------------------------------------------------------------------------

    /// The next half-edge (counter-clockwise) in the same face.
    #[inline]
    pub fn next(&self, h: HalfedgeId) -> HalfedgeId {
        HalfedgeId::from_index(self.he_next[h.index()] as usize)
    }

    /// The previous half-edge in the same face (`next(next(h))` on triangles).
    #[inline]
    pub fn prev(&self, h: HalfedgeId) -> HalfedgeId {
        self.next(self.next(h))
    }

    /// The oppositely directed half-edge of the same edge (`h ^ 1`).
    #[inline]
    pub fn twin(&self, h: HalfedgeId) -> HalfedgeId {
        h.twin()
    }

    /// The vertex `h` points to.
    #[inline]
    pub fn head(&self, h: HalfedgeId) -> VertexId {
        VertexId::from_index(self.he_head[h.index()] as usize)
    }

    /// The vertex `h` leaves (`head(twin(h))`).
    #[inline]
    pub fn tail(&self, h: HalfedgeId) -> VertexId {
        self.head(h.twin())
    }

    /// The undirected edge of `h` (`h >> 1`).
    #[inline]
    pub fn edge(&self, h: HalfedgeId) -> EdgeId {
        h.edge()
    }

    /// The face `h` belongs to.
    #[inline]
    pub fn face(&self, h: HalfedgeId) -> FaceId {
        FaceId::from_index(self.he_face[h.index()] as usize)
    }

    /// One half-edge of face `f`; [`Mesh::face_vertices`] starts at its tail.
    #[inline]
    pub fn halfedge_of_face(&self, f: FaceId) -> HalfedgeId {
        HalfedgeId::from_index(self.f_halfedge[f.index()] as usize)
    }

    /// One half-edge leaving vertex `v`.
    #[inline]
    pub fn halfedge_of_vertex(&self, v: VertexId) -> HalfedgeId {
        HalfedgeId::from_index(self.v_halfedge[v.index()] as usize)
    }

    /// The canonical half-edge (`2e`) of edge `e`.
    #[inline]
    pub fn edge_halfedge(&self, e: EdgeId) -> HalfedgeId {
        e.halfedge()
    }

    /// The two endpoints `[tail, head]` of edge `e`'s canonical half-edge.
    #[inline]
    pub fn edge_vertices(&self, e: EdgeId) -> [VertexId; 2] {
        let h = e.halfedge();
        [self.tail(h), self.head(h)]
    }

    /// The vertex of `h`'s face that is not on `h` (`head(next(h))`).
    #[inline]
    pub fn opposite_vertex(&self, h: HalfedgeId) -> VertexId {
        self.head(self.next(h))
    }

    /// The three half-edges of `f`, starting at [`Mesh::halfedge_of_face`].
    #[inline]
    pub fn face_halfedges(&self, f: FaceId) -> [HalfedgeId; 3] {
        let h0 = self.halfedge_of_face(f);
        let h1 = self.next(h0);
        [h0, h1, self.next(h1)]
    }

    /// The three corners of `f` in counter-clockwise order, starting at the tail of
    /// [`Mesh::halfedge_of_face`].
    #[inline]
    pub fn face_vertices(&self, f: FaceId) -> [VertexId; 3] {
        let [h0, h1, h2] = self.face_halfedges(f);
        [self.head(h2), self.head(h0), self.head(h1)]
    }

    // ----- liveness and counts ----------------------------------------------------------------

    /// Whether `v` is a live vertex of this mesh (false for tombstones and out-of-range ids).
    #[inline]
    pub fn is_vertex_alive(&self, v: VertexId) -> bool {
        self.v_alive.get(v.index()).copied().unwrap_or(false)
    }

    /// Whether `f` is a live face of this mesh.
    #[inline]
    pub fn is_face_alive(&self, f: FaceId) -> bool {
        self.f_alive.get(f.index()).copied().unwrap_or(false)
    }

    /// Whether `e` is a live edge of this mesh.
    #[inline]
    pub fn is_edge_alive(&self, e: EdgeId) -> bool {
        self.e_alive.get(e.index()).copied().unwrap_or(false)
    }

    /// Whether `h` is a live half-edge (its edge is live).
    #[inline]
    pub fn is_halfedge_alive(&self, h: HalfedgeId) -> bool {
        self.is_edge_alive(h.edge())
    }

    /// Number of live vertices.
    #[inline]
    pub fn n_vertices(&self) -> usize {
        self.n_live_vertices
    }

    /// Number of live faces.
    #[inline]
    pub fn n_faces(&self) -> usize {
        self.n_live_faces
    }

    /// Number of live edges.
    #[inline]
    pub fn n_edges(&self) -> usize {
        self.n_live_edges
    }

    /// Number of live half-edges (`2 · n_edges`).
    #[inline]
    pub fn n_halfedges(&self) -> usize {
        2 * self.n_live_edges
    }

    /// Number of vertex slots (live and dead): the length a per-vertex array must have.
    #[inline]
    pub fn vertex_capacity(&self) -> usize {
        self.v_alive.len()
    }

    /// Number of face slots (live and dead): the length a per-face array must have.
    #[inline]
    pub fn face_capacity(&self) -> usize {
        self.f_alive.len()
    }

    /// Number of edge slots (live and dead): the length a per-edge array must have.
    #[inline]
    pub fn edge_capacity(&self) -> usize {
        self.e_alive.len()
    }

    /// Live vertices in increasing id order.
    pub fn vertices(&self) -> impl Iterator<Item = VertexId> + '_ {
        live_ids(&self.v_alive).map(VertexId::from_index)
    }

    /// Live faces in increasing id order.
    pub fn faces(&self) -> impl Iterator<Item = FaceId> + '_ {
        live_ids(&self.f_alive).map(FaceId::from_index)
    }

    /// Live edges in increasing id order.
    pub fn edges(&self) -> impl Iterator<Item = EdgeId> + '_ {
        live_ids(&self.e_alive).map(EdgeId::from_index)
    }

    /// Live half-edges in increasing id order (both halves of every live edge).
    pub fn halfedges(&self) -> impl Iterator<Item = HalfedgeId> + '_ {
        self.edges().flat_map(|e| {
            let h = e.halfedge();
            [h, h.twin()]
        })
    }

    // ----- positions and geometry -------------------------------------------------------------

    /// Position of vertex `v`.
    #[inline]
    pub fn position(&self, v: VertexId) -> DVec3 {
        self.positions[v.index()]
    }

    /// Moves vertex `v` to `p`.
    #[inline]
    pub fn set_position(&mut self, v: VertexId, p: DVec3) {
        self.positions[v.index()] = p;
    }

    /// All positions, indexed by `VertexId::index()`; dead slots may hold anything.
    #[inline]
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// All positions, mutable (e.g. for an optimizer step); dead slots are ignored by the mesh.
    #[inline]
    pub fn positions_mut(&mut self) -> &mut [DVec3] {
        &mut self.positions
    }

    /// `(p1 − p0) × (p2 − p0)` of face `f`: twice its area times its unit normal.
    #[inline]
    pub fn face_cross(&self, f: FaceId) -> DVec3 {
        let [a, b, c] = self.face_vertices(f).map(|v| self.position(v));
        (b - a).cross(c - a)
    }

    /// Unit normal of `f`; faces with `|cross| <= 1e-9` get `(1, 0, 0)`.
    pub fn face_normal(&self, f: FaceId) -> DVec3 {
        let [a, b, c] = self.face_vertices(f).map(|v| self.position(v));
        crate::triangle::triangle_normal(a, b, c)
    }

    /// Area of `f`, clamped below at `1e-9` so that no ratio of areas is NaN.
    pub fn face_area(&self, f: FaceId) -> f64 {
        (0.5 * self.face_cross(f).length()).max(DEGENERATE_CROSS)
    }

    /// Centroid of face `f`.
    pub fn face_centroid(&self, f: FaceId) -> DVec3 {
        let [a, b, c] = self.face_vertices(f).map(|v| self.position(v));
        (a + b + c) / 3.0
    }

    /// Euclidean length of edge `e`.
    pub fn edge_length(&self, e: EdgeId) -> f64 {
        let [a, b] = self.edge_vertices(e);
        self.position(a).distance(self.position(b))
    }

    /// Signed volume enclosed by the live faces (positive for outward orientation).
    pub fn signed_volume(&self) -> f64 {
        self.faces()
            .map(|f| {
                let [a, b, c] = self.face_vertices(f).map(|v| self.position(v));
                a.dot(b.cross(c))
            })
            .sum::<f64>()
            / 6.0
    }

    /// Total area of the live faces (unclamped).
    pub fn surface_area(&self) -> f64 {
        self.faces()
            .map(|f| 0.5 * self.face_cross(f).length())
            .sum()
    }

    // ----- allocation (crate-internal, used by the operators) ---------------------------------

    /// Appends a live vertex at `p` with no half-edge yet.
    pub(crate) fn push_vertex(&mut self, p: DVec3) -> VertexId {
        let v = VertexId::from_index(self.v_alive.len());
        self.positions.push(p);
        self.v_halfedge.push(INVALID);
        self.v_alive.push(true);
        self.n_live_vertices += 1;
        v
    }

    /// Appends a live face with no half-edge yet.
    pub(crate) fn push_face(&mut self) -> FaceId {
        let f = FaceId::from_index(self.f_alive.len());
        self.f_halfedge.push(INVALID);
        self.f_alive.push(true);
        self.n_live_faces += 1;
        f
    }

    /// Appends a live edge (two half-edges, unlinked) and returns its canonical half-edge.
    pub(crate) fn push_edge(&mut self) -> HalfedgeId {
        let e = EdgeId::from_index(self.e_alive.len());
        for _ in 0..2 {
            self.he_next.push(INVALID);
            self.he_head.push(INVALID);
            self.he_face.push(INVALID);
        }
        self.e_alive.push(true);
        self.n_live_edges += 1;
        e.halfedge()
    }

    /// Sets `next`, `head` and `face` of `h` in one go.
    #[inline]
    pub(crate) fn link(&mut self, h: HalfedgeId, next: HalfedgeId, head: VertexId, face: FaceId) {
        self.he_next[h.index()] = next.raw();
        self.he_head[h.index()] = head.raw();
        self.he_face[h.index()] = face.raw();
    }

    /// Sets the three half-edges of face `f` to the cycle `hs[0] → hs[1] → hs[2]` with the given
    /// heads, and points `f` at `hs[0]`.
    pub(crate) fn set_triangle(&mut self, f: FaceId, hs: [HalfedgeId; 3], heads: [VertexId; 3]) {
        for k in 0..3 {
            self.link(hs[k], hs[(k + 1) % 3], heads[k], f);
        }
        self.f_halfedge[f.index()] = hs[0].raw();
    }

    #[inline]
    pub(crate) fn set_vertex_halfedge(&mut self, v: VertexId, h: HalfedgeId) {
        self.v_halfedge[v.index()] = h.raw();
    }

    pub(crate) fn kill_vertex(&mut self, v: VertexId) {
        debug_assert!(self.v_alive[v.index()]);
        self.v_alive[v.index()] = false;
        self.v_halfedge[v.index()] = INVALID;
        self.n_live_vertices -= 1;
    }

    pub(crate) fn kill_face(&mut self, f: FaceId) {
        debug_assert!(self.f_alive[f.index()]);
        self.f_alive[f.index()] = false;
        self.f_halfedge[f.index()] = INVALID;
        self.n_live_faces -= 1;
    }

    pub(crate) fn kill_edge(&mut self, e: EdgeId) {
        debug_assert!(self.e_alive[e.index()]);
        self.e_alive[e.index()] = false;
        let h = e.halfedge().index();
        for i in [h, h + 1] {
            self.he_next[i] = INVALID;
            self.he_head[i] = INVALID;
            self.he_face[i] = INVALID;
        }
        self.n_live_edges -= 1;
    }
}

/// Indices of the `true` entries of `alive`, in order.
fn live_ids(alive: &[bool]) -> impl Iterator<Item = usize> + '_ {
    alive
        .iter()
        .enumerate()
        .filter_map(|(i, &a)| a.then_some(i))
}
