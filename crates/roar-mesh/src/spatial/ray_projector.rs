//! Exact projection of source samples onto a target triangle soup by ray casting, guarded by
//! winding numbers of the current source mesh, after the authors' later code
//! (`project_to_triangle_soup`; `docs/method.md#projection-onto-the-target`).

use glam::DVec3;
use rayon::prelude::*;

use super::bvh::{RayHit, TriangleBvh};
use super::projector::Projector;
use super::winding::WindingNumber;

/// Offset of the ray origins from the sample along ∓n, so a sample on the target still hits it.
const ORIGIN_OFFSET: f64 = 1e-6;

/// Samples per parallel work item.
const CHUNK: usize = 2048;

/// Options of [`RayCastProjector`]; the defaults are the authors' code's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayProjectorOptions {
    /// Largest accepted |τ| (signed move along the normal). Default 0.05.
    pub max_distance: f64,
    /// A hit whose target face normal `m` has `|m·n| ≤` this is oblique: the sample stays valid
    /// but does not move. Default 0.7.
    pub oblique_gate: f64,
}

impl Default for RayProjectorOptions {
    fn default() -> Self {
        Self {
            max_distance: 0.05,
            oblique_gate: 0.7,
        }
    }
}

/// Ray-cast [`Projector`] onto a fixed target triangle soup.
///
/// Per sample `s` with unit normal `n`: casts `s + 1e-6 n` along `−n` and `s − 1e-6 n` along
/// `+n` (unbounded, nearest hit each). For each hit with move `p` (sample → hit point), the
/// winding number `w` of the **current source mesh** at `a = s + 0.1p` and `b = s + 1.1p` must
/// satisfy `w(a) ∈ [−0.5, 1.5]` and `|w(a)| > 0.5 ⇔ |w(b)| > 0.5`, else the hit is dropped.
/// "Both inside": when both rays hit (before the guards) and both `a` points have `|w| > 0.5`,
/// the sample is invalid. Otherwise the nearer surviving hit gives the signed move τ; valid iff
/// `|τ| ≤ max_distance`. An oblique hit (`|m·n| ≤ oblique_gate`) returns `q = s`.
#[derive(Debug, Clone)]
pub struct RayCastProjector {
    bvh: TriangleBvh,
    options: RayProjectorOptions,
}

/// One ray's nearest hit: signed move τ along n, and |m·n| of the hit face.
#[derive(Debug, Clone, Copy)]
struct SignedHit {
    tau: f64,
    facing: f64,
}

impl RayCastProjector {
    /// Builds the BVH of the target soup. Faces with out-of-range indices or non-finite corners
    /// are left out (see [`TriangleBvh::build`]).
    pub fn new(
        target_positions: &[DVec3],
        target_triangles: &[[u32; 3]],
        options: &RayProjectorOptions,
    ) -> Self {
        Self {
            bvh: TriangleBvh::build(target_positions, target_triangles),
            options: *options,
        }
    }

    /// The options in use.
    pub fn options(&self) -> &RayProjectorOptions {
        &self.options
    }

    /// The nearest hits along −n and +n of one sample (no guards yet).
    fn cast(&self, s: DVec3, n: DVec3) -> [Option<SignedHit>; 2] {
        let signed = |hit: Option<RayHit>, sign: f64| -> Option<SignedHit> {
            let hit = hit?;
            let [a, b, c] = self.bvh.corners(hit.face);
            let m = (b - a).cross(c - a).normalize_or_zero();
            let tau = sign * (hit.t - ORIGIN_OFFSET);
            tau.is_finite().then_some(SignedHit {
                tau,
                facing: m.dot(n).abs(),
            })
        };
        let back = self.bvh.ray_cast(s + ORIGIN_OFFSET * n, -n, f64::INFINITY);
        let front = self.bvh.ray_cast(s - ORIGIN_OFFSET * n, n, f64::INFINITY);
        [signed(back, -1.0), signed(front, 1.0)]
    }

    /// Decides one sample from its hits and the winding numbers at `(a, b)` of each hit.
    fn decide(
        &self,
        s: DVec3,
        n: DVec3,
        hits: [Option<SignedHit>; 2],
        windings: [[f64; 2]; 2],
    ) -> Option<DVec3> {
        let inside = |w: f64| w.abs() > 0.5;
        let both_hit = hits[0].is_some() && hits[1].is_some();
        if both_hit && inside(windings[0][0]) && inside(windings[1][0]) {
            return None;
        }
        let mut best: Option<SignedHit> = None;
        for (hit, [wa, wb]) in hits.into_iter().zip(windings) {
            let Some(hit) = hit else { continue };
            let guarded = (-0.5..=1.5).contains(&wa) && inside(wa) == inside(wb);
            if guarded && best.is_none_or(|b| hit.tau.abs() < b.tau.abs()) {
                best = Some(hit);
            }
        }
        let best = best?;
        if best.tau.abs() > self.options.max_distance {
            return None;
        }
        if best.facing <= self.options.oblique_gate {
            return Some(s);
        }
        let q = s + best.tau * n;
        q.is_finite().then_some(q)
    }
}

impl Projector for RayCastProjector {
    fn project(
        &self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        points: &[DVec3],
        normals: &[DVec3],
    ) -> Vec<Option<DVec3>> {
        let Ok(winding) = WindingNumber::build(positions, triangles) else {
            return vec![None; points.len()];
        };
        let work = |start: usize, chunk: &[DVec3]| -> Vec<Option<DVec3>> {
            chunk
                .iter()
                .enumerate()
                .map(|(i, &s)| {
                    let n = *normals.get(start + i)?;
                    if !s.is_finite() || !n.is_finite() || n == DVec3::ZERO {
                        return None;
                    }
                    let hits = self.cast(s, n);
                    let windings = hits.map(|h| match h {
                        Some(h) => {
                            let p = h.tau * n;
                            [
                                winding.winding_number(s + 0.1 * p),
                                winding.winding_number(s + 1.1 * p),
                            ]
                        }
                        None => [0.0, 0.0],
                    });
                    self.decide(s, n, hits, windings)
                })
                .collect()
        };
        if points.len() <= CHUNK {
            return work(0, points);
        }
        points
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(c, chunk)| work(c * CHUNK, chunk))
            .collect::<Vec<_>>()
            .concat()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unit cube [0,1]³ (outward).
    fn cube(lo: f64, hi: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for i in 0..8 {
            let c = |bit: usize| if i & bit != 0 { hi } else { lo };
            p.push(DVec3::new(c(1), c(2), c(4)));
        }
        let t = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        (p, t)
    }

    #[test]
    fn sample_inside_a_slightly_larger_target_moves_outward() {
        let (sp, st) = cube(0.0, 1.0);
        let (tp, tt) = cube(-0.02, 1.02);
        let proj = RayCastProjector::new(&tp, &tt, &RayProjectorOptions::default());
        let s = DVec3::new(1.0, 0.4, 0.6);
        let q = proj.project(&sp, &st, &[s], &[DVec3::X]);
        let q = q[0].unwrap();
        assert!((q - DVec3::new(1.02, 0.4, 0.6)).length() < 1e-9, "{q}");
        // Too far: beyond max_distance.
        let (tp, tt) = cube(-0.2, 1.2);
        let proj = RayCastProjector::new(&tp, &tt, &RayProjectorOptions::default());
        assert_eq!(proj.project(&sp, &st, &[s], &[DVec3::X])[0], None);
    }

    #[test]
    fn oblique_hit_keeps_sample_in_place() {
        let (sp, st) = cube(0.0, 1.0);
        // Target plane tilted by 60° from the sample normal.
        let m = DVec3::new(0.5, 0.0, 3f64.sqrt() / 2.0);
        let u = m.any_orthonormal_vector();
        let v = m.cross(u);
        let c = DVec3::new(1.01, 0.5, 0.5);
        let tp = vec![c - u - v, c + u - v, c + u + v, c - u + v];
        let tt = vec![[0, 1, 2], [0, 2, 3]];
        let proj = RayCastProjector::new(&tp, &tt, &RayProjectorOptions::default());
        let s = DVec3::new(1.0, 0.5, 0.5);
        assert_eq!(proj.project(&sp, &st, &[s], &[DVec3::X])[0], Some(s));
    }

    #[test]
    fn missing_normals_and_empty_targets_give_none() {
        let (sp, st) = cube(0.0, 1.0);
        let proj = RayCastProjector::new(&[], &[], &RayProjectorOptions::default());
        let out = proj.project(&sp, &st, &[DVec3::X, DVec3::Y], &[DVec3::X]);
        assert_eq!(out, vec![None, None]);
    }
}
