//! The sequential decimation: [`decimate`] and [`decimate_with`], and the [`Decimator`] that
//! pops, checks and applies the collapses (also for each side of
//! [`decimate_in_parallel`](super::decimate_in_parallel)).

use super::budget::check_request;
use super::error::DecimateError;
use super::grid::{Box32, FaceGrid};
use super::heap::EdgeHeap;
use super::options::DecimateOptions;
use super::slab::Slab;
use super::stats::{DecimateStats, VetoCounts};
use crate::geometry::is_degenerate;
use crate::quadric::{Quadric, placement};
use glam::DVec3;
use roar_mesh::spatial::{Aabb, triangle_quality};
use roar_mesh::spatial::{
    PreparedFace, certainly_apart, faces_intersect_filtered, fan_is_embedded,
};
use roar_mesh::{Collapse, EdgeId, FaceId, HalfedgeId, Mesh, VertexId};

/// Decimates `mesh` to exactly `target_faces` faces; see the module docs and
/// [`decimate_with`] (this is it without a collapse callback).
pub fn decimate(
    mesh: &mut Mesh,
    target_faces: usize,
    options: &DecimateOptions,
) -> Result<DecimateStats, DecimateError> {
    decimate_with(mesh, target_faces, options, |_| {})
}

/// Decimates `mesh` to exactly `target_faces` faces, calling `on_collapse` after every applied
/// collapse (before the final compaction), so callers can keep per-vertex data in step: the
/// survivor `head(h)` keeps its id (and, for the optimizer, its row: `Optimizer::on_collapse`
/// is not needed); it is moved to the quadric placement. At the end the mesh is compacted and
/// the [`Remap`](roar_mesh::Remap) returned in the stats.
///
/// Promises: the mesh stays valid (closed, oriented, 2-manifold), components and genera are
/// unchanged, no collapse creates a self-intersection (with `check_self_intersections`), and
/// `n_faces() == target_faces` on `Ok` unless `best_effort` or `noop` say otherwise.
///
/// Errors: [`DecimateError::OddTarget`], [`DecimateError::TargetBelowMinimum`] (checked up
/// front, mesh unchanged), [`DecimateError::BudgetNotReached`] (mesh left at the closest count,
/// compacted), [`DecimateError::InvalidOption`]. A target at or above the current count is a
/// no-op (`stats.noop`).
pub fn decimate_with(
    mesh: &mut Mesh,
    target_faces: usize,
    options: &DecimateOptions,
    on_collapse: impl FnMut(&Collapse),
) -> Result<DecimateStats, DecimateError> {
    let initial = mesh.n_faces();
    if let Some(noop) = check_request(mesh, target_faces, options)? {
        return Ok(noop);
    }
    let mut run = Decimator::new(mesh, options, None, on_collapse);
    let mut last_pass = VetoCounts::default();
    let mut bound_used = options.quality_bounds[0];
    'bounds: for &bound in &options.quality_bounds {
        bound_used = bound;
        for _ in 0..options.max_passes_per_bound {
            let before = run.mesh.n_faces();
            last_pass = run.pass(target_faces, bound);
            if run.mesh.n_faces() <= target_faces {
                break 'bounds;
            }
            if run.mesh.n_faces() == before {
                break;
            }
        }
    }
    let stats_core = (run.collapses, run.vetoes, run.passes, run.max_cost);
    drop(run);
    let remap = mesh.compact();
    let final_faces = mesh.n_faces();
    let reached = final_faces == target_faces;
    if !reached && !options.best_effort {
        return Err(DecimateError::BudgetNotReached {
            target: target_faces,
            reached: final_faces,
            reasons: last_pass,
        });
    }
    Ok(DecimateStats {
        initial_faces: initial,
        final_faces,
        target: target_faces,
        reached_target: reached,
        noop: false,
        collapses: stats_core.0,
        vetoes: stats_core.1,
        quality_bound: Some(bound_used),
        passes: stats_core.2,
        max_cost: stats_core.3,
        remap: Some(remap),
    })
}

/// Why a collapse was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Veto {
    NormalFlip,
    Degenerate,
    Quality,
    SelfIntersection,
}

/// What to do with a popped collapse.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Verdict {
    Collapse,
    /// Put it back with its cost multiplied by this quality penalty (> 1).
    Penalize(f64),
    Refuse(Veto),
}

pub(super) struct Decimator<'m, F: FnMut(&Collapse)> {
    mesh: &'m mut Mesh,
    options: &'m DecimateOptions,
    on_collapse: F,
    quadrics: Vec<Quadric>,
    /// Placement of each queued edge's collapse (valid while the edge is in `heap`).
    targets: Vec<DVec3>,
    /// Whether each queued edge's heap cost already includes its quality penalty.
    penalized: Vec<bool>,
    /// Smallest cost of a collapse (see the module doc).
    cost_floor: f64,
    heap: EdgeHeap,
    grid: Option<FaceGrid>,
    /// Faces in the grid when it was last rebuilt, and now (it is rebuilt with larger cells
    /// when half of them are gone).
    grid_faces: usize,
    grid_live: usize,
    /// When set, only collapses whose star and placement lie inside this slab are made, and the
    /// grid holds only the faces with a corner inside (module `split`: no other face can meet
    /// a face such a collapse creates).
    region: Option<Slab>,
    /// Scratch: the corners (before the collapse) of the fan of the collapse being checked.
    fan: Vec<[VertexId; 3]>,
    /// Scratch: the fan's faces after the collapse (relabelled corners) and their boxes.
    fan_scratch: Vec<(PreparedFace, Box32)>,
    /// Scratch: unmoved faces near the fan.
    near_scratch: Vec<NearFace>,
    /// Scratch: the rim edges of the fan after the collapse (see [`fan_is_embedded`]).
    rim_scratch: Vec<[DVec3; 2]>,
    pub(super) collapses: usize,
    vetoes: VetoCounts,
    pub(super) passes: usize,
    pub(super) max_cost: f64,
}

/// Weight, relative to its face's plane, of the plane through the edge of halfedge `h`
/// perpendicular to its face (`normal`): `planar_weight`, plus `crease_weight` times the edge's
/// sharpness `s = (1 − n₁·n₂)/2` (0 where the surface is flat, ½ at a right angle, 1 where it
/// folds back onto itself).
///
/// Why: at a sharp rim the two face planes nearly coincide (a thin flap, folded back) or one of
/// them is a sliver of little area (the side of a thin plate), so moving the rim into the part
/// costs almost nothing and the decimation eats thin parts from their rims. The plane through
/// the rim perpendicular to the face is exactly the one that such a move leaves.
fn edge_plane_weight(mesh: &Mesh, h: HalfedgeId, normal: DVec3, options: &DecimateOptions) -> f64 {
    let mut weight = options.planar_weight;
    if options.crease_weight > 0.0 {
        let other = mesh.face_normal(mesh.face(h.twin()));
        let sharpness = 0.5 * (1.0 - normal.dot(other));
        if sharpness.is_finite() {
            weight += options.crease_weight * sharpness;
        }
    }
    weight
}

/// A face the grid query of the intersection veto found near a collapse's fan: its corner ids
/// and grid box, and, once asked for, the face prepared for the plane tests.
///
/// Why lazily: the query covers the box of the whole fan, and most faces it returns overlap no
/// single fan face's box, so they are never tested; preparing them up front read their corner
/// positions (scattered, cache misses) and computed their plane minors for nothing.
#[derive(Debug, Clone, Copy)]
struct NearFace {
    ids: [u32; 3],
    bx: Box32,
    prepared: Option<PreparedFace>,
}

impl NearFace {
    fn new(ids: [u32; 3], bx: Box32) -> NearFace {
        NearFace {
            ids,
            bx,
            prepared: None,
        }
    }

    /// The face prepared with its corners at `positions[ids]`: computed at the first call and
    /// kept, so `positions` must not change between calls.
    #[inline]
    fn prepared(&mut self, positions: &[DVec3]) -> &PreparedFace {
        let ids = self.ids;
        self.prepared
            .get_or_insert_with(|| PreparedFace::new(ids, ids.map(|v| positions[v as usize])))
    }
}

/// Corners of `f` as raw ids, and their box.
fn face_corners_and_box(mesh: &Mesh, f: FaceId) -> ([u32; 3], Aabb) {
    let c = mesh.face_vertices(f);
    (
        c.map(|v| v.raw()),
        Aabb::from_triangle(c.map(|v| mesh.position(v))),
    )
}

impl<'m, F: FnMut(&Collapse)> Decimator<'m, F> {
    pub(super) fn new(
        mesh: &'m mut Mesh,
        options: &'m DecimateOptions,
        region: Option<Slab>,
        on_collapse: F,
    ) -> Self {
        let mut quadrics = vec![Quadric::default(); mesh.vertex_capacity()];
        // With a region, only the faces with a corner inside contribute: the quadric of every
        // vertex inside is then complete (summed in the same face order, so bit for bit the
        // same), and a vertex outside never takes part in a collapse, so its partial quadric
        // only sets the heap cost of edges that are popped and skipped.
        let contributes = |f: FaceId| {
            region.is_none_or(|slab| {
                mesh.face_vertices(f)
                    .iter()
                    .any(|&v| slab.contains(mesh.position(v)))
            })
        };
        for f in mesh.faces().filter(|&f| contributes(f)) {
            let cross = mesh.face_cross(f);
            let len = cross.length();
            if !(len > 0.0 && len.is_finite()) {
                continue;
            }
            let area = 0.5 * len;
            let normal = cross / len;
            let q = Quadric::from_plane(normal, mesh.face_centroid(f), area);
            let corners = mesh.face_vertices(f);
            for v in corners {
                quadrics[v.index()] = quadrics[v.index()].add(&q);
            }
            for h in mesh.face_halfedges(f) {
                let weight = area * edge_plane_weight(mesh, h, normal, options);
                if weight <= 0.0 {
                    continue;
                }
                let (a, b) = (mesh.tail(h), mesh.head(h));
                let (pa, pb) = (mesh.position(a), mesh.position(b));
                let across = normal.cross(pb - pa).normalize_or_zero();
                let q = Quadric::from_plane(across, pa, weight);
                for v in [a, b] {
                    quadrics[v.index()] = quadrics[v.index()].add(&q);
                }
            }
        }
        let diagonal = Aabb::from_points(mesh.vertices().map(|v| mesh.position(v)))
            .map_or(0.0, |b| b.diagonal());
        // Area × squared distance, far below any real error (1e-8 of the diagonal off a plane
        // over the whole bounding box), yet positive so that penalties order flat collapses.
        let cost_floor = if diagonal.is_finite() {
            1e-16 * diagonal.powi(4)
        } else {
            0.0
        };
        let mut d = Decimator {
            targets: vec![DVec3::ZERO; mesh.edge_capacity()],
            penalized: vec![false; mesh.edge_capacity()],
            cost_floor,
            heap: EdgeHeap::new(mesh.edge_capacity()),
            mesh,
            options,
            on_collapse,
            quadrics,
            grid: None,
            grid_faces: 0,
            grid_live: 0,
            region,
            fan: Vec::new(),
            fan_scratch: Vec::new(),
            near_scratch: Vec::new(),
            rim_scratch: Vec::new(),
            collapses: 0,
            vetoes: VetoCounts::default(),
            passes: 0,
            max_cost: 0.0,
        };
        if options.check_self_intersections {
            d.rebuild_grid();
        }
        d
    }

    /// Rebuilds the face grid with cells of twice the current mean edge length (of the faces
    /// it holds: all, or those with a corner in the region).
    fn rebuild_grid(&mut self) {
        let mesh = &*self.mesh;
        let region = self.region;
        let inside = |v: VertexId| region.is_none_or(|slab| slab.contains(mesh.position(v)));
        let (sum, n) = mesh
            .edges()
            .filter(|&e| mesh.edge_vertices(e).into_iter().any(inside))
            .fold((0.0, 0usize), |(s, n), e| (s + mesh.edge_length(e), n + 1));
        let mean = if n > 0 { sum / n as f64 } else { 1.0 };
        let cell = if mean > 0.0 && mean.is_finite() {
            2.0 * mean
        } else {
            1.0
        };
        let faces: Vec<FaceId> = mesh
            .faces()
            .filter(|&f| mesh.face_vertices(f).into_iter().any(inside))
            .collect();
        let mut grid = FaceGrid::new(cell, mesh.face_capacity(), faces.len());
        for &f in &faces {
            let (corners, bx) = face_corners_and_box(mesh, f);
            grid.insert(f.raw(), corners, &bx);
        }
        self.grid = Some(grid);
        self.grid_faces = faces.len();
        self.grid_live = faces.len();
    }

    /// Cost and placement of collapsing `e` under the current quadrics; records the placement.
    fn evaluate(&mut self, e: EdgeId) -> f64 {
        let [u, v] = self.mesh.edge_vertices(e);
        let q = self.quadrics[u.index()].add(&self.quadrics[v.index()]);
        let (target, cost) = placement(&q, self.mesh.position(u), self.mesh.position(v));
        self.targets[e.index()] = target;
        self.penalized[e.index()] = false;
        let relief = (self.removed_quality(e.halfedge()) / self.options.quality_bounds[0]).max(1.0);
        cost.max(self.cost_floor) / relief
    }

    /// The aspect ratio of `corners`, clamped to `degenerate_quality`.
    fn clamped_quality(&self, corners: [DVec3; 3]) -> f64 {
        triangle_quality(corners).min(self.options.degenerate_quality)
    }

    /// The worst clamped aspect ratio of the two faces a collapse of `h` removes.
    fn removed_quality(&self, h: HalfedgeId) -> f64 {
        [self.mesh.face(h), self.mesh.face(h.twin())]
            .into_iter()
            .map(|f| {
                self.clamped_quality(self.mesh.face_vertices(f).map(|v| self.mesh.position(v)))
            })
            .fold(1.0, f64::max)
    }

    /// One pass: queue every live edge, then collapse cheapest first until the target is
    /// reached or the heap is empty. Returns the vetoes of this pass.
    pub(super) fn pass(&mut self, target_faces: usize, bound: f64) -> VetoCounts {
        self.passes += 1;
        let edges: Vec<EdgeId> = match self.region {
            None => self.mesh.edges().collect(),
            Some(slab) => self
                .mesh
                .edges()
                .filter(|&e| {
                    let [u, v] = self.mesh.edge_vertices(e);
                    slab.contains(self.mesh.position(u)) && slab.contains(self.mesh.position(v))
                })
                .collect(),
        };
        let entries: Vec<(f64, u32)> = edges.iter().map(|&e| (self.evaluate(e), e.raw())).collect();
        self.heap.rebuild(entries);
        let mut vetoes = VetoCounts::default();
        while self.mesh.n_faces() > target_faces {
            let Some((cost, edge)) = self.heap.pop() else {
                break;
            };
            let e = EdgeId::from_index(edge as usize);
            let h = e.halfedge();
            if self.mesh.can_collapse(h).is_err() {
                vetoes.topology += 1;
                continue;
            }
            let target = self.targets[e.index()];
            if self
                .region
                .is_some_and(|slab| !slab.holds_collapse(self.mesh, h, target))
            {
                continue;
            }
            let penalized = self.penalized[e.index()];
            match self.judge(h, target, bound, penalized) {
                Verdict::Refuse(Veto::NormalFlip) => vetoes.normal_flip += 1,
                Verdict::Refuse(Veto::Degenerate) => vetoes.degenerate += 1,
                Verdict::Refuse(Veto::Quality) => vetoes.quality += 1,
                Verdict::Refuse(Veto::SelfIntersection) => vetoes.self_intersection += 1,
                Verdict::Penalize(factor) => {
                    self.penalized[e.index()] = true;
                    self.heap.set(edge, cost * factor);
                }
                Verdict::Collapse => {
                    self.apply(h, target);
                    self.max_cost = self.max_cost.max(cost);
                }
            }
        }
        self.vetoes.add(&vetoes);
        vetoes
    }

    /// Fills `self.fan` with the faces that survive a collapse of `h` and change shape (all
    /// faces around both endpoints except the two on the edge), with their current corners.
    fn collect_fan(&mut self, h: HalfedgeId) {
        let mesh = &*self.mesh;
        let (a, b) = (mesh.tail(h), mesh.head(h));
        let gone = [mesh.face(h), mesh.face(h.twin())];
        self.fan.clear();
        for v in [a, b] {
            for o in mesh.outgoing(v) {
                let face = mesh.face(o);
                if gone.contains(&face) {
                    continue;
                }
                // Outgoing `o: v → x` lies in the counter-clockwise face (v, x, head(next(o))).
                let corners = [v, mesh.head(o), mesh.head(mesh.next(o))];
                self.fan.push(corners);
            }
        }
    }

    /// The geometric vetoes of the module doc, in order of cost, and the quality penalty: a
    /// collapse not yet `penalized` whose worst new face earns a penalty is sent back to the
    /// heap before the (expensive) intersection test.
    fn judge(&mut self, h: HalfedgeId, p: DVec3, bound: f64, penalized: bool) -> Verdict {
        self.collect_fan(h);
        let mesh = &*self.mesh;
        let (a, b) = (mesh.tail(h), mesh.head(h));
        let moved = |v: VertexId| {
            if v == a || v == b {
                p
            } else {
                mesh.position(v)
            }
        };
        let mut q_new = 1.0f64;
        for corners in &self.fan {
            let old = corners.map(|v| mesh.position(v));
            let new = corners.map(moved);
            let cross_new = (new[1] - new[0]).cross(new[2] - new[0]);
            let longest = (0..3)
                .map(|i| new[i].distance_squared(new[(i + 1) % 3]))
                .fold(0.0, f64::max);
            let area2 = cross_new.length();
            if area2.is_nan() || area2 <= 1e-10 * longest {
                return Verdict::Refuse(Veto::Degenerate);
            }
            // A degenerate face's old normal is noise: it cannot flip.
            let cross_old = (old[1] - old[0]).cross(old[2] - old[0]);
            if cross_old.length() > 0.0
                && cross_old.normalize().dot(cross_new.normalize()) <= self.options.min_normal_dot
                && !is_degenerate(triangle_quality(old), self.options.degenerate_quality)
            {
                return Verdict::Refuse(Veto::NormalFlip);
            }
            q_new = q_new.max(self.clamped_quality(new));
        }
        // The replaced faces' worst quality (the removed ones included) matters only above the
        // bound (rarely), so it is computed only then.
        if q_new > bound {
            let q_old = self
                .fan
                .iter()
                .map(|c| self.clamped_quality(c.map(|v| mesh.position(v))))
                .fold(self.removed_quality(h), f64::max);
            if q_new > q_old {
                return Verdict::Refuse(Veto::Quality);
            }
        }
        let above = self.options.quality_penalty_above;
        if !penalized && above > 0.0 && q_new > above {
            return Verdict::Penalize(q_new / above);
        }
        if self.grid.is_some() && self.creates_intersection(h, p) {
            return Verdict::Refuse(Veto::SelfIntersection);
        }
        Verdict::Collapse
    }

    /// Whether a face of the fan (with `tail(h)`, `head(h)` merged at `p`) intersects any
    /// other face. Needs [`Self::collect_fan`] first. Moves the two endpoints to `p` for the
    /// test and restores them.
    ///
    /// Faces outside the fan do not move: they are tested against each new fan face through
    /// the grid (boxes stored in the grid are current for them). Fan faces are tested against
    /// each other once per pair.
    fn creates_intersection(&mut self, h: HalfedgeId, p: DVec3) -> bool {
        let (a, b) = (self.mesh.tail(h), self.mesh.head(h));
        let (pa, pb) = (self.mesh.position(a), self.mesh.position(b));
        self.mesh.set_position(a, p);
        self.mesh.set_position(b, p);
        let mesh = &*self.mesh;
        let grid = self.grid.as_ref().expect("grid exists when checking");
        let positions = mesh.positions();
        let corners_of = |t: [u32; 3]| t.map(|v| positions[v as usize]);
        let relabel = |c: [VertexId; 3]| c.map(|v| if v == a { b.raw() } else { v.raw() });
        // The faces of the star of `a` or `b` (the fan and the two removed faces) are exactly
        // the faces with `a` or `b` as a corner; the grid stores every face's current corners.
        let (a_raw, b_raw) = (a.raw(), b.raw());
        let in_star = |corners: [u32; 3]| corners.contains(&a_raw) || corners.contains(&b_raw);
        // The new fan faces, prepared for the plane tests, with their boxes, and the box of
        // them all (rounded outward to `f32`, like the grid's: a box test only filters pairs
        // for the exact test, so a slightly larger box never changes the answer).
        let fan = &mut self.fan_scratch;
        fan.clear();
        let mut all: Option<Box32> = None;
        for &c in &self.fan {
            let ids = relabel(c);
            let corners = corners_of(ids);
            let bx = Box32::around(&Aabb::from_triangle(corners));
            all = Some(all.map_or(bx, |a| a.union(&bx)));
            fan.push((PreparedFace::new(ids, corners), bx));
        }
        // One grid query for the whole fan: the unmoved faces near it.
        let near = &mut self.near_scratch;
        near.clear();
        if let Some(all) = all {
            grid.query(&all, |_, g_box, ids| {
                if !in_star(ids) {
                    near.push(NearFace::new(ids, *g_box));
                }
            });
        }
        // The fan's own pairs need no test when the fan is certainly embedded (the common case).
        let rim = &mut self.rim_scratch;
        rim.clear();
        rim.extend(
            self.fan
                .iter()
                .map(|c| [c[1], c[2]].map(|v| positions[v.index()])),
        );
        let test_fan_pairs = !fan_is_embedded(p, rim);
        // A pair is tested exactly unless the prepared plane tests prove it apart.
        let meet = |x: &PreparedFace, y: &PreparedFace| {
            !certainly_apart(x, y) && faces_intersect_filtered(positions, x.ids, y.ids)
        };
        let mut hit = false;
        'fan: for (i, (tri, bx)) in fan.iter().enumerate() {
            for (other, other_box) in fan[i + 1..].iter().filter(|_| test_fan_pairs) {
                if other_box.overlaps(bx) && meet(tri, other) {
                    hit = true;
                    break 'fan;
                }
            }
            for other in near.iter_mut() {
                if other.bx.overlaps(bx) && meet(tri, other.prepared(positions)) {
                    hit = true;
                    break 'fan;
                }
            }
        }
        self.mesh.set_position(a, pa);
        self.mesh.set_position(b, pb);
        hit
    }

    fn apply(&mut self, h: HalfedgeId, p: DVec3) {
        let (a, b) = (self.mesh.tail(h), self.mesh.head(h));
        let q = self.quadrics[a.index()].add(&self.quadrics[b.index()]);
        let c = self
            .mesh
            .collapse(h)
            .unwrap_or_else(|e| panic!("qem: collapse checked by can_collapse failed (bug): {e}"));
        self.mesh.set_position(b, p);
        self.quadrics[b.index()] = q;
        self.collapses += 1;
        (self.on_collapse)(&c);
        for e in c.removed_edges {
            self.heap.remove(e.raw());
        }
        if let Some(grid) = self.grid.as_mut() {
            // The removed faces held the collapsed edge, so they were in the grid.
            self.grid_live -= c.removed_faces.len();
            for f in c.removed_faces {
                grid.remove(f.raw());
            }
            for f in self.mesh.faces_around(b) {
                let (corners, bx) = face_corners_and_box(self.mesh, f);
                grid.update(f.raw(), corners, &bx);
            }
        }
        let start = self.mesh.halfedge_of_vertex(b);
        let mut o = start;
        loop {
            let e = o.edge();
            let cost = self.evaluate(e);
            self.heap.set(e.raw(), cost);
            o = self.mesh.prev(o).twin();
            if o == start {
                break;
            }
        }
        if self.grid.is_some() && 2 * self.grid_live < self.grid_faces {
            self.rebuild_grid();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_face_is_prepared_once_from_its_corners() {
        let positions = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let bx = Box32::around(&Aabb::from_triangle([DVec3::ZERO, DVec3::X, DVec3::Z]));
        let mut near = NearFace::new([0, 1, 3], bx);
        assert!(near.prepared.is_none());
        let first = *near.prepared(&positions);
        assert_eq!(first.ids, [0, 1, 3]);
        assert_eq!(first.corners, [DVec3::ZERO, DVec3::X, DVec3::Z]);
        // Kept: a later call does not read the positions again.
        let moved = [DVec3::ONE; 4];
        assert_eq!(near.prepared(&moved).corners, first.corners);
    }
}
