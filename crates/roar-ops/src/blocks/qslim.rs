//! ROAR's QSlim edge cost and placement, as in the authors' code
//! (`docs/method.md#collapse-cost-and-placement`), with the collapse validity simulation that
//! the Face Collapse and Face Split blocks share.
//!
//! Per vertex a quadric `(A, b, c)` sums planes `(n, d = −n·x0)` as `A += w n nᵀ`,
//! `b += w d n`, `c += w d²`: the planes of its faces (weight 100, no area weighting), the
//! bisector planes of its edges (weight 1) and its own "vertex plane" (weight 100). The cost of
//! collapsing edge (a, b) onto endpoint position p is `pᵀ(A_a+A_b)p + 2(b_a+b_b)·p + c_a+c_b`,
//! clamped at 0; placements are the two endpoints only (half-edge collapse).

use crate::geometry::Geometry;
use crate::quadric::Quadric;
use roar_mesh::spatial::triangle_quality;
use roar_mesh::{DEGENERATE_CROSS, DVec3, EdgeId, HalfedgeId, Mesh, VertexId};

/// How the vertex plane's "generalized normal" blends the vertex normal with the Laplacian
/// (`docs/method.md#decision-vertex-plane-of-the-collapse-cost`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VertexPlane {
    /// The authors' code: `ñ = normalize(N_v |N_v|² + δ_v (1 − |N_v|)²)` with the raw area×angle
    /// weighted normal `N_v`. `|N_v|` scales with the squared edge length, so on fine meshes the
    /// plane follows the Laplacian direction δ_v. Default, the behaviour the paper's results came
    /// from.
    #[default]
    RawMagnitude,
    /// Scale-free variant (ours): `|N_v|` replaced by μ_v, i.e.
    /// `ñ = normalize(n_v μ_v³ + δ_v (1 − μ_v)²)`; on flat patches (μ = 1) the plane is the
    /// tangent plane, so in-plane collapses are free.
    NormalizedMagnitude,
    /// No vertex plane at all.
    None,
}

/// Weights of the three plane families; the defaults are the authors' code's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QSlimOptions {
    /// Weight of each face plane at its three vertices. Default 100.
    pub face_weight: f64,
    /// Weight of each edge bisector plane at its two endpoints. Default 1.
    pub edge_weight: f64,
    /// Weight of the vertex plane. Default 100.
    pub vertex_weight: f64,
    /// Vertex plane variant. Default [`VertexPlane::RawMagnitude`].
    pub vertex_plane: VertexPlane,
}

impl Default for QSlimOptions {
    fn default() -> Self {
        Self {
            face_weight: 100.0,
            edge_weight: 1.0,
            vertex_weight: 100.0,
            vertex_plane: VertexPlane::RawMagnitude,
        }
    }
}

/// Per-vertex quadrics (by vertex slot) of the current mesh.
pub fn vertex_quadrics(mesh: &Mesh, geometry: &Geometry, options: &QSlimOptions) -> Vec<Quadric> {
    let mut q = vec![Quadric::default(); mesh.vertex_capacity()];
    for f in mesh.faces() {
        let vs = mesh.face_vertices(f);
        let n = geometry.face_normals[f.index()];
        let x0 = mesh.position(vs[0]);
        for v in vs {
            q[v.index()].add_plane(n, x0, options.face_weight);
        }
    }
    for e in mesh.edges() {
        let h = e.halfedge();
        let (a, b) = (mesh.tail(h), mesh.head(h));
        let n_l = geometry.face_normals[mesh.face(h).index()];
        let n_r = geometry.face_normals[mesh.face(h.twin()).index()];
        let n = edge_bisector(n_l, n_r, mesh.position(b) - mesh.position(a));
        let x0 = mesh.position(a);
        q[a.index()].add_plane(n, x0, options.edge_weight);
        q[b.index()].add_plane(n, x0, options.edge_weight);
    }
    if options.vertex_plane != VertexPlane::None {
        for v in mesh.vertices() {
            let n = generalized_vertex_normal(mesh, geometry, v, options.vertex_plane);
            q[v.index()].add_plane(n, mesh.position(v), options.vertex_weight);
        }
    }
    q
}

/// Normal of the bisector plane of an edge: `n_L` rotated about the edge by half the signed
/// dihedral, i.e. `normalize(n_L + n_R)` (both are perpendicular to the edge). For a fully
/// folded edge (`n_L = −n_R`) it is the in-between direction `ê × n_L` (its sign does not
/// matter for a quadric).
pub fn edge_bisector(n_l: DVec3, n_r: DVec3, edge: DVec3) -> DVec3 {
    let s = n_l + n_r;
    let len = s.length();
    if len > 1e-9 {
        s / len
    } else {
        edge.normalize_or_zero().cross(n_l).normalize_or(n_l)
    }
}

/// The vertex plane's generalized normal ([`VertexPlane`]); falls back to the unit vertex
/// normal, then to +x, when the blend vanishes.
pub fn generalized_vertex_normal(
    mesh: &Mesh,
    geometry: &Geometry,
    v: VertexId,
    variant: VertexPlane,
) -> DVec3 {
    let p = mesh.position(v);
    let (mut sum, mut count) = (DVec3::ZERO, 0.0);
    for u in mesh.neighbors(v) {
        sum += mesh.position(u);
        count += 1.0;
    }
    let laplacian = if count > 0.0 {
        p - sum / count
    } else {
        DVec3::ZERO
    };
    let blend = match variant {
        VertexPlane::RawMagnitude | VertexPlane::None => {
            let raw = geometry.vertex_normals_raw[v.index()];
            let m = raw.length();
            raw * (m * m) + laplacian * (1.0 - m).powi(2)
        }
        VertexPlane::NormalizedMagnitude => {
            let mu = geometry.normal_magnitude[v.index()];
            geometry.vertex_normals[v.index()] * mu.powi(3) + laplacian * (1.0 - mu).powi(2)
        }
    };
    blend
        .try_normalize()
        .or_else(|| geometry.vertex_normals[v.index()].try_normalize())
        .unwrap_or(DVec3::X)
}

/// Validity rules of the collapse simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValidityOptions {
    /// Reject a placement if a resulting face has quality `Q` above this; `None` disables the
    /// check. The Face Split block uses `Some(5.0)` (supplementary §1.2); fold removal uses
    /// `None`, as the authors' code (`docs/method.md#decision-fold-estimator-and-its-gates`).
    pub max_quality: Option<f64>,
    /// Edges shorter than this skip both checks. Default 1e-5 (the authors' code).
    pub skip_checks_below_length: f64,
}

impl Default for ValidityOptions {
    fn default() -> Self {
        Self {
            max_quality: None,
            skip_checks_below_length: 1e-5,
        }
    }
}

/// Cost and placement of the best valid collapse of an edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCost {
    /// QSlim cost (≥ 0) of the chosen placement.
    pub cost: f64,
    /// The endpoint whose position survives.
    pub keep: VertexId,
    /// The half-edge pointing *to* `keep`: `mesh.collapse(halfedge)` merges the other endpoint
    /// into `keep`, which keeps its position and its optimizer row.
    pub halfedge: HalfedgeId,
}

/// Why no placement of an edge is valid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Invalid {
    /// Some incident face would flip (for at least one placement).
    Flip,
    /// Some resulting face would exceed the quality threshold (and no placement flipped).
    Quality,
}

impl Invalid {
    /// The stats key of this reason.
    pub fn reason(self) -> &'static str {
        match self {
            Invalid::Flip => "flip",
            Invalid::Quality => "quality",
        }
    }
}

/// The QSlim cost of collapsing edge `e` onto the better of its two valid endpoint placements
/// (module docs), or why neither is valid. Ties go to the edge's head.
///
/// Validity of "keep k, remove r": no face around r (other than the two faces of `e`, which
/// vanish) flips when r moves to k (`n_before · n_after < 0`; faces degenerate before or after
/// do not count), and, if enabled, none of those faces ends with `Q > max_quality` (a NaN Q
/// counts as 1). The faces around k do not move, so they cannot change. Only the faces that
/// change are quality-checked (our reading; the paper does not say), so an already bad
/// neighbour of k does not veto.
pub fn edge_cost(
    mesh: &Mesh,
    quadrics: &[Quadric],
    e: EdgeId,
    options: &ValidityOptions,
) -> Result<EdgeCost, Invalid> {
    let h = e.halfedge();
    let (a, b) = (mesh.tail(h), mesh.head(h));
    let q = quadrics[a.index()].add(&quadrics[b.index()]);
    let skip = mesh.edge_length(e) < options.skip_checks_below_length;
    let mut best: Option<EdgeCost> = None;
    let mut failure = None;
    // Placement "keep b" (collapse h: a → b) first, then "keep a" (collapse twin: b → a).
    for (keep, remove, he) in [(b, a, h), (a, b, h.twin())] {
        if !skip && let Err(why) = placement_valid(mesh, remove, keep, options) {
            failure = Some(match (failure, why) {
                (Some(Invalid::Flip), _) | (_, Invalid::Flip) => Invalid::Flip,
                _ => Invalid::Quality,
            });
            continue;
        }
        let cost = q.eval(mesh.position(keep));
        if best.is_none_or(|bc| cost < bc.cost) {
            best = Some(EdgeCost {
                cost,
                keep,
                halfedge: he,
            });
        }
    }
    best.ok_or(failure.unwrap_or(Invalid::Flip))
}

/// A lower bound of the QSlim cost of edge `e`: the smaller clamped quadric value of its two
/// endpoint placements, without the validity simulation. It is computed with the same
/// arithmetic as [`edge_cost`], whose cost (when `Ok`) is one of these two values, so
/// `edge_cost(mesh, quadrics, e, options)?.cost >= edge_cost_lower_bound(mesh, quadrics, e)`
/// holds exactly, for every `options`.
pub fn edge_cost_lower_bound(mesh: &Mesh, quadrics: &[Quadric], e: EdgeId) -> f64 {
    let h = e.halfedge();
    let (a, b) = (mesh.tail(h), mesh.head(h));
    let q = quadrics[a.index()].add(&quadrics[b.index()]);
    let keep_b = q.eval(mesh.position(b));
    let keep_a = q.eval(mesh.position(a));
    keep_b.min(keep_a)
}

/// Simulates moving `remove` onto `keep`'s position (they share an edge) and checks the faces
/// around `remove` that survive the collapse.
fn placement_valid(
    mesh: &Mesh,
    remove: VertexId,
    keep: VertexId,
    options: &ValidityOptions,
) -> Result<(), Invalid> {
    let target = mesh.position(keep);
    let mut quality_failed = false;
    for f in mesh.faces_around(remove) {
        let vs = mesh.face_vertices(f);
        if vs.contains(&keep) {
            continue; // one of the two faces of the edge: it disappears
        }
        let before = vs.map(|v| mesh.position(v));
        let after = vs.map(|v| {
            if v == remove {
                target
            } else {
                mesh.position(v)
            }
        });
        let n0 = (before[1] - before[0]).cross(before[2] - before[0]);
        let n1 = (after[1] - after[0]).cross(after[2] - after[0]);
        if n0.length() > DEGENERATE_CROSS && n1.length() > DEGENERATE_CROSS && n0.dot(n1) < 0.0 {
            return Err(Invalid::Flip);
        }
        if let Some(max_q) = options.max_quality {
            let q = triangle_quality(after);
            if !q.is_nan() && q > max_q {
                quality_failed = true;
            }
        }
    }
    if quality_failed {
        Err(Invalid::Quality)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_quadric_measures_squared_distance() {
        let mut q = Quadric::default();
        let n = DVec3::new(1.0, 2.0, 2.0) / 3.0;
        let x0 = DVec3::new(0.5, -1.0, 2.0);
        q.add_plane(n, x0, 2.0);
        let p = DVec3::new(3.0, 1.0, -1.0);
        let d = n.dot(p - x0);
        assert!((q.eval(p) - 2.0 * d * d).abs() < 1e-12);
        assert!(q.eval(x0).abs() < 1e-12);
    }

    #[test]
    fn lower_bound_never_exceeds_the_cost() {
        let mesh = roar_mesh::shapes::perturbed(&roar_mesh::shapes::icosphere(3), 0.01, 4);
        let g = Geometry::compute(&mesh);
        let q = vertex_quadrics(&mesh, &g, &QSlimOptions::default());
        let strict = ValidityOptions {
            max_quality: Some(5.0),
            ..ValidityOptions::default()
        };
        let (mut valid, mut tight) = (0, 0);
        for e in mesh.edges() {
            let lower = edge_cost_lower_bound(&mesh, &q, e);
            for options in [ValidityOptions::default(), strict] {
                if let Ok(c) = edge_cost(&mesh, &q, e, &options) {
                    assert!(c.cost >= lower, "{e:?}: {} < {lower}", c.cost);
                    valid += 1;
                    tight += usize::from(c.cost == lower);
                }
            }
        }
        assert!(
            valid > 1000 && tight > valid / 2,
            "{valid} valid, {tight} tight"
        );
    }

    #[test]
    fn bisector_of_folded_edge_is_perpendicular_to_both() {
        let n = edge_bisector(DVec3::Z, -DVec3::Z, DVec3::X);
        assert!(n.dot(DVec3::Z).abs() < 1e-12 && n.dot(DVec3::X).abs() < 1e-12);
        let n = edge_bisector(DVec3::Z, DVec3::Y, DVec3::X);
        assert!((n - DVec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-12);
    }
}
