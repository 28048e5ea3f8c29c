//! The options of a decimation ([`DecimateOptions`]) and their validation.

use super::error::DecimateError;

/// Options of [`decimate`](super::decimate). `Default` gives the values used by the pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct DecimateOptions {
    /// A collapse is vetoed if some face around the merged vertex has `n_before · n_after ≤
    /// min_normal_dot` (unit normals). Default 0.2 (a face may turn by up to ~78°). Must lie in
    /// [-1, 1).
    pub min_normal_dot: f64,
    /// Successive bounds on the aspect ratio `Q = R/(2r)` (1 for an equilateral triangle) of the
    /// faces a collapse creates; the next bound is used only when the previous one blocks the
    /// budget. Each must be ≥ 1. Default `[10, 20, 100]`:
    /// - a first bound of 5 only costs fidelity, with the soft `quality_penalty_above` shaping
    ///   the faces (Chamfer/diag decimating to 1000 faces with penalty and planar terms on,
    ///   bound 5 / 10 / 20: roar's 5000-face cgal-non_manifold_face_graph 2.94e-3 / 2.74e-3 /
    ///   2.65e-3; the 5000-face init of manifoldplus-chair 4.05e-3 / 3.45e-3 / 3.40e-3);
    /// - the last step, up to `degenerate_quality`, is for inputs strewn with slivers, such as
    ///   marching extractions: on the 2.6 M-face marching tetrahedra extraction of a neural SDF
    ///   (`docs/sdf.md`), every collapse left at 11,586 faces toward 5,000 made a face above 20
    ///   worse than any it replaced.
    pub quality_bounds: Vec<f64>,
    /// Soft preference for well-shaped faces (default 2; 0 turns it off): a collapse whose worst
    /// new face has aspect ratio `Q` above this costs `Q / quality_penalty_above` times its
    /// quadric error, as in MeshLab's quality-weighted QEM (vcglib divides the error by the
    /// worst new face's quality below a threshold of 0.3 on its scale, about `Q = 2` on ours).
    /// Must be 0 or ≥ 1.
    pub quality_penalty_above: f64,
    /// Weight, relative to the face's own plane, of the planes through each face edge
    /// perpendicular to the face that are added to the edge's end quadrics (MeshLab's "planar
    /// simplification"; default 1e-3, 0 = off). In flat and cylindrical regions the face planes
    /// leave the placement and cost undecided; these small terms keep merged vertices near the
    /// original edges and make a collapse that distorts the flat layout cost more, which keeps
    /// triangles well shaped.
    ///
    /// Measured with `quality_penalty_above` (decimating to 1000 faces, Chamfer/diag and median
    /// aspect ratio, old defaults → new): roar's 5000-face output of cgal-non_manifold_face_graph
    /// 3.22e-3, 1.58 → 2.74e-3, 1.24; the 5000-face init of manifoldplus-chair 4.31e-3, 1.92 →
    /// 3.45e-3, 1.88; of luke-f-16 2.32e-3, 1.71 → 2.26e-3, 1.61. On clean organic meshes (spot,
    /// homer, rocker-arm) the planar terms cost 1–3 % Chamfer for a better median aspect ratio.
    pub planar_weight: f64,
    /// Weight, relative to the face's own plane, of the same edge planes at sharp edges, scaled
    /// by the edge's sharpness (`(1 − n₁·n₂)/2`: 0 flat, ½ at a right angle, 1 folded back);
    /// default 1, 0 = off. It keeps a collapse from sliding a rim into the part behind it,
    /// which the face planes barely notice at a thin part's rim (see `edge_plane_weight`).
    pub crease_weight: f64,
    /// Aspect ratio from which a face counts as degenerate (default 100, must be ≥ the last
    /// quality bound). Such a face's normal is rounding noise and its exact ratio says nothing
    /// more, so the vetoes and the penalty compare ratios clamped to this value, the normal
    /// veto ignores such a face's old normal, and a collapse that removes one costs less (its
    /// error divided by the removed face's clamped ratio over the first quality bound). Without
    /// this, the zero-width caps the optimization leaves along creases survive the QEM: their
    /// normals flip at random, which the normal veto refuses, and every collapse in a strip of
    /// them makes another cap, which the quality veto refuses. Measured on roar's 10000-face
    /// loop output of cgal-non_manifold_face_graph decimated to 5000 faces (faces above 100,
    /// 95th-percentile aspect ratio, Chamfer/diag), before → after: 303, 201, 1.824e-3 → 31,
    /// 2.21, 1.819e-3; of manifoldplus-chair: 13 → 3 faces above 100, Chamfer/diag equal.
    pub degenerate_quality: f64,
    /// Run the self-intersection veto (default `true`). Switching it off makes decimation
    /// faster but may create intersections.
    pub check_self_intersections: bool,
    /// Re-queue all edges at most this many times per quality bound (default 8).
    pub max_passes_per_bound: usize,
    /// When the budget cannot be reached: `false` (default) returns
    /// [`DecimateError::BudgetNotReached`]; `true` keeps the closest mesh and returns `Ok` with
    /// [`DecimateStats::reached_target`](super::DecimateStats::reached_target) false.
    pub best_effort: bool,
}

impl Default for DecimateOptions {
    fn default() -> Self {
        Self {
            min_normal_dot: 0.2,
            quality_bounds: vec![10.0, 20.0, 100.0],
            quality_penalty_above: 2.0,
            planar_weight: 1e-3,
            crease_weight: 1.0,
            degenerate_quality: crate::geometry::DEGENERATE_QUALITY,
            check_self_intersections: true,
            max_passes_per_bound: 8,
            best_effort: false,
        }
    }
}

pub(super) fn check_options(o: &DecimateOptions) -> Result<(), DecimateError> {
    let bad = |name, reason| Err(DecimateError::InvalidOption { name, reason });
    if !(-1.0..1.0).contains(&o.min_normal_dot) {
        return bad("min_normal_dot", "a value in [-1, 1)");
    }
    if o.quality_bounds.is_empty() || o.quality_bounds.iter().any(|&q| q.is_nan() || q < 1.0) {
        return bad("quality_bounds", "a non-empty list of values >= 1");
    }
    let p = o.quality_penalty_above;
    if !(p == 0.0 || (p >= 1.0 && p.is_finite())) {
        return bad("quality_penalty_above", "0 (off) or a finite value >= 1");
    }
    if !(o.planar_weight >= 0.0 && o.planar_weight.is_finite()) {
        return bad("planar_weight", "a finite value >= 0");
    }
    if !(o.crease_weight >= 0.0 && o.crease_weight.is_finite()) {
        return bad("crease_weight", "a finite value >= 0");
    }
    let last_bound = o.quality_bounds.last().copied().unwrap_or(1.0);
    if !(o.degenerate_quality >= last_bound && o.degenerate_quality.is_finite()) {
        return bad(
            "degenerate_quality",
            "a finite value >= the last quality bound",
        );
    }
    if o.max_passes_per_bound == 0 {
        return bad("max_passes_per_bound", "at least 1");
    }
    Ok(())
}
