//! A filtered front end to the exact [`faces_intersect`]: cheap floating-point plane-side tests
//! that are certain (Shewchuk's static error bound for `orient3d`) settle the common "clearly
//! apart" cases without allocation; everything else goes to the exact test. Shared by everything
//! that tests many face pairs: the self-intersection count, the QEM intersection veto, the
//! untangle block and the step limiter.

use super::tri_tri::faces_intersect;
use glam::DVec3;

/// Shewchuk's `o3derrboundA = (7 + 56ε)ε` with `ε = 2⁻⁵³`.
const O3D_ERR_BOUND: f64 = (7.0 + 56.0 * f64::EPSILON / 2.0) * (f64::EPSILON / 2.0);

/// The sign of `orient3d(a, b, c, d)` when the floating-point evaluation certifies it, else
/// `None` (the exact value may be zero or of either sign). `Some(0)` is never returned.
#[inline]
fn certain_orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<i8> {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let bdxcdy = bd.x * cd.y;
    let cdxbdy = cd.x * bd.y;
    let cdxady = cd.x * ad.y;
    let adxcdy = ad.x * cd.y;
    let adxbdy = ad.x * bd.y;
    let bdxady = bd.x * ad.y;
    let det = ad.z * (bdxcdy - cdxbdy) + bd.z * (cdxady - adxcdy) + cd.z * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * ad.z.abs()
        + (cdxady.abs() + adxcdy.abs()) * bd.z.abs()
        + (adxbdy.abs() + bdxady.abs()) * cd.z.abs();
    certain_sign(det, O3D_ERR_BOUND * permanent)
}

/// The sign of `det` when its magnitude exceeds the error `bound`, else `None`.
#[inline]
fn certain_sign(det: f64, bound: f64) -> Option<i8> {
    if det > bound {
        Some(1)
    } else if -det > bound {
        Some(-1)
    } else {
        None
    }
}

/// Shewchuk's `ccwerrboundA = (3 + 16ε)ε` with `ε = 2⁻⁵³`.
const O2D_ERR_BOUND: f64 = (3.0 + 16.0 * f64::EPSILON / 2.0) * (f64::EPSILON / 2.0);

/// The sign of `orient2d(a, b, c)` on coordinates `(x, y) = (p[i], p[j])` when the
/// floating-point evaluation certifies it, else `None`.
#[inline]
fn certain_orient2d(i: usize, j: usize, a: DVec3, b: DVec3, c: DVec3) -> Option<i8> {
    let left = (a[i] - c[i]) * (b[j] - c[j]);
    let right = (a[j] - c[j]) * (b[i] - c[i]);
    certain_sign(left - right, O2D_ERR_BOUND * (left.abs() + right.abs()))
}

/// The two coordinate axes kept when dropping the largest component of `n`.
fn projection_axes(n: DVec3) -> (usize, usize) {
    let a = n.abs();
    if a.x >= a.y && a.x >= a.z {
        (1, 2)
    } else if a.y >= a.z {
        (2, 0)
    } else {
        (0, 1)
    }
}

/// A certified separating line in the projection on axes `(i, j)`: an edge `(p, q)` of one
/// face, through every corner it shares with the other face, with the face's third corner
/// strictly on one side and every unshared corner of the other face strictly on the other.
///
/// Why that proves the faces meet only in their shared corners: the projections then meet only
/// on the edge's line, at projections of shared corners (or along the shared edge), and the
/// projection is one-to-one on the first face (its projected area is certified non-zero).
fn separated_in_projection(
    (i, j): (usize, usize),
    (ta, pa): ([u32; 3], [DVec3; 3]),
    (tb, pb): ([u32; 3], [DVec3; 3]),
    n_shared: usize,
) -> bool {
    // By reference: an array of the two orders by value was copied with `memcpy` on every call.
    for (t, pt, u, pu) in [(&ta, &pa, &tb, &pb), (&tb, &pb, &ta, &pa)] {
        'edges: for k in 0..3 {
            let (p, q, r) = (k, (k + 1) % 3, (k + 2) % 3);
            let on_edge = u.contains(&t[p]) as usize + u.contains(&t[q]) as usize;
            if on_edge != n_shared {
                continue;
            }
            let Some(side) = certain_orient2d(i, j, pt[p], pt[q], pt[r]) else {
                continue;
            };
            for m in 0..3 {
                if t.contains(&u[m]) {
                    continue;
                }
                if certain_orient2d(i, j, pt[p], pt[q], pu[m]) != Some(-side) {
                    continue 'edges;
                }
            }
            return true;
        }
    }
    false
}

/// True if every point of `points` is certainly strictly on one side of the plane `t`.
#[inline]
fn all_strictly_one_side(t: [DVec3; 3], points: &[DVec3]) -> bool {
    let mut side = 0i8;
    for &p in points {
        match certain_orient3d(t[0], t[1], t[2], p) {
            Some(s) if side == 0 || s == side => side = s,
            _ => return false,
        }
    }
    true
}

/// Whether the closed triangles `a` and `b` intersect, when floating-point filters certify
/// every sign the decision needs (`None` otherwise: a corner (nearly) on the other's plane, or
/// the two crossing segments (nearly) touching).
///
/// Devillers and Guigue's test ("Faster triangle-triangle intersection tests", 2002): if the
/// corners of one triangle are all strictly on one side of the other's plane, they do not
/// meet. Otherwise each triangle crosses the other's plane in a segment on the common line of
/// the planes, and they meet iff the segments overlap. With the corners renamed so that
/// `a[0]` is alone on its side of `b`'s plane and `b[0]` alone on its side of `a`'s, both on
/// the negative side (`b[1]`, `b[2]` or `a[1]`, `a[2]` swapped if needed; Shewchuk's sign
/// convention, `orient3d(p, q, r, s) = det[p − s; q − s; r − s]`), the segments overlap iff
/// `orient3d(b0, a0, b1, a1) ≤ 0` and `orient3d(b0, a2, b2, a0) ≤ 0`. Every sign used here is
/// certified non-zero, so no tie decides the answer. Degenerate (collinear) triangles have all
/// corners on each other's plane and get `None`.
fn certain_crossing(a: [DVec3; 3], b: [DVec3; 3]) -> Option<bool> {
    let side = |t: [DVec3; 3], p: DVec3| certain_orient3d(t[0], t[1], t[2], p);
    let sa = [side(b, a[0])?, side(b, a[1])?, side(b, a[2])?];
    if sa[0] == sa[1] && sa[1] == sa[2] {
        return Some(false);
    }
    let sb = [side(a, b[0])?, side(a, b[1])?, side(a, b[2])?];
    if sb[0] == sb[1] && sb[1] == sb[2] {
        return Some(false);
    }
    // `a[alone]` is the corner of `a` alone on its side of `b`'s plane: rotate it to the front.
    let alone_a = (0..3).find(|&i| sa[i] != sa[(i + 1) % 3] && sa[i] != sa[(i + 2) % 3])?;
    let a = [a[alone_a], a[(alone_a + 1) % 3], a[(alone_a + 2) % 3]];
    let mut b = b;
    let mut sb = sb;
    // Make `a[0]` negative for `b`'s plane by flipping `b`'s orientation if needed (the sides
    // of `b`'s corners for `a`'s plane only move with the swap); then the same for `b[0]`.
    if sa[alone_a] > 0 {
        b.swap(1, 2);
        sb.swap(1, 2);
    }
    let alone_b = (0..3).find(|&j| sb[j] != sb[(j + 1) % 3] && sb[j] != sb[(j + 2) % 3])?;
    let b = [b[alone_b], b[(alone_b + 1) % 3], b[(alone_b + 2) % 3]];
    let mut a = a;
    if sb[alone_b] > 0 {
        a.swap(1, 2);
    }
    let first = certain_orient3d(b[0], a[0], b[1], a[1])?;
    let second = certain_orient3d(b[0], a[2], b[2], a[0])?;
    Some(first < 0 && second < 0)
}

/// Same answer as [`faces_intersect`] whenever a face is not degenerate (collinear faces that
/// `faces_intersect` conservatively reports may be reported only where they really meet).
///
/// Fast negatives, each certified by a floating-point filter with Shewchuk's error bounds: no
/// shared index and one face strictly on one side of the other's plane; one shared index and
/// the other two corners of one face strictly on one side of the other's plane (then the faces
/// meet only at the shared corner); a shared edge whose two opposite corners are certainly not
/// coplanar with it; and, for (near-)coplanar faces, a separating edge line in a coordinate
/// projection (see `separated_in_projection`). Flat regions make the exact predicates take
/// their slow, exact-arithmetic path, which these filters mostly avoid.
pub fn faces_intersect_filtered(positions: &[DVec3], ta: [u32; 3], tb: [u32; 3]) -> bool {
    let n = positions.len();
    if ta.iter().chain(&tb).any(|&i| i as usize >= n) {
        return faces_intersect(positions, ta, tb);
    }
    let pa = ta.map(|i| positions[i as usize]);
    let pb = tb.map(|i| positions[i as usize]);
    // Corners of each face that are not shared with the other.
    let mut only_a = [DVec3::ZERO; 3];
    let mut only_b = [DVec3::ZERO; 3];
    let (mut na, mut nb) = (0, 0);
    for i in 0..3 {
        if !tb.contains(&ta[i]) {
            only_a[na] = pa[i];
            na += 1;
        }
        if !ta.contains(&tb[i]) {
            only_b[nb] = pb[i];
            nb += 1;
        }
    }
    let apart = match (na, nb) {
        (3, 3) => match certain_crossing(pa, pb) {
            Some(crossing) => return crossing,
            None => all_strictly_one_side(pa, &only_b) || all_strictly_one_side(pb, &only_a),
        },
        (2, 2) => {
            all_strictly_one_side(pa, &only_b[..nb]) || all_strictly_one_side(pb, &only_a[..na])
        }
        // A shared edge: the opposite corners are off the plane of the other face.
        (1, 1) => certain_orient3d(pa[0], pa[1], pa[2], only_b[0]).is_some(),
        _ => return faces_intersect(positions, ta, tb),
    };
    if apart {
        return false;
    }
    let n_shared = 3 - na;
    let axes_a = projection_axes((pa[1] - pa[0]).cross(pa[2] - pa[0]));
    let axes_b = projection_axes((pb[1] - pb[0]).cross(pb[2] - pb[0]));
    if separated_in_projection(axes_a, (ta, pa), (tb, pb), n_shared)
        || (axes_b != axes_a && separated_in_projection(axes_b, (ta, pa), (tb, pb), n_shared))
    {
        return false;
    }
    faces_intersect(positions, ta, tb)
}

/// A face prepared for many certified plane-side tests: its corner ids and positions, and the
/// 2×2 minors of its plane, so that one test costs three products instead of a whole
/// `orient3d` (the QEM intersection veto tests each new face against dozens of others).
///
/// [`PreparedFace::side`] evaluates `orient3d` with the face's first corner `c0` as the pivot,
/// `det[q − c0; c1 − c0; c2 − c0]`, expanded along the row `q − c0`: the transpose of the
/// matrix Shewchuk's `orient3dfast` expands along its last column. Each of the nine entries is
/// one rounded difference of input coordinates and the evaluation has the same shape (three
/// rounded products of an entry with a rounded 2×2 minor, summed left to right), so his error
/// bound `o3derrboundA × permanent` certifies the sign exactly as in [`certain_orient3d`]; the
/// minors and the minors' halves of the permanent depend on the face alone and are computed
/// once.
#[derive(Debug, Clone, Copy)]
pub struct PreparedFace {
    /// Corner ids (as given to [`faces_intersect`]).
    pub ids: [u32; 3],
    /// Corner positions.
    pub corners: [DVec3; 3],
    /// Rounded minors `(bd_y cd_z − bd_z cd_y, bd_z cd_x − bd_x cd_z, bd_x cd_y − bd_y cd_x)`
    /// of `bd = c1 − c0`, `cd = c2 − c0`.
    minors: DVec3,
    /// The matching sums of absolute products (`|bd_y cd_z| + |bd_z cd_y|`, …).
    weights: DVec3,
}

impl PreparedFace {
    /// Prepares the face with corner ids `ids` at `corners`.
    pub fn new(ids: [u32; 3], corners: [DVec3; 3]) -> PreparedFace {
        let bd = corners[1] - corners[0];
        let cd = corners[2] - corners[0];
        let (yz, zy) = (bd.y * cd.z, bd.z * cd.y);
        let (zx, xz) = (bd.z * cd.x, bd.x * cd.z);
        let (xy, yx) = (bd.x * cd.y, bd.y * cd.x);
        PreparedFace {
            ids,
            corners,
            minors: DVec3::new(yz - zy, zx - xz, xy - yx),
            weights: DVec3::new(
                yz.abs() + zy.abs(),
                zx.abs() + xz.abs(),
                xy.abs() + yx.abs(),
            ),
        }
    }

    /// Bits `i` of the points `points[i]` certainly strictly above (first mask) and below
    /// (second mask) the face's plane. Branch-free: the pair tests run millions of times with
    /// unpredictable outcomes.
    #[inline]
    fn side_masks(&self, points: &[DVec3; 3]) -> (u8, u8) {
        let (mut above, mut below) = (0u8, 0u8);
        for (i, &q) in points.iter().enumerate() {
            let ad = q - self.corners[0];
            let (m, w) = (self.minors, self.weights);
            let det = ad.x * m.x + ad.y * m.y + ad.z * m.z;
            let permanent = ad.x.abs() * w.x + ad.y.abs() * w.y + ad.z.abs() * w.z;
            let bound = O3D_ERR_BOUND * permanent;
            above |= u8::from(det > bound) << i;
            below |= u8::from(-det > bound) << i;
        }
        (above, below)
    }

    /// Whether `other`'s corners outside the mask `shared` (bit `i`: corner `i` is one of this
    /// face's corners) are all certainly strictly on one side of this face's plane.
    #[inline]
    fn others_strictly_one_side(&self, other: &PreparedFace, shared: u8) -> bool {
        let (above, below) = self.side_masks(&other.corners);
        (above | shared) == 0b111 || (below | shared) == 0b111
    }

    /// Bit `i` set when corner `i` of this face is a corner of `other`.
    #[inline]
    fn shared_mask(&self, other: &PreparedFace) -> u8 {
        let mut mask = 0u8;
        for (i, &v) in self.ids.iter().enumerate() {
            let found = (v == other.ids[0]) | (v == other.ids[1]) | (v == other.ids[2]);
            mask |= u8::from(found) << i;
        }
        mask
    }

    /// Whether the three corner ids differ.
    #[inline]
    fn has_distinct_ids(&self) -> bool {
        let [x, y, z] = self.ids;
        (x != y) & (y != z) & (x != z)
    }
}

/// True only if the two faces certainly do not intersect in the sense of [`faces_intersect`]:
/// the corners of one face that are not shared with the other lie certainly strictly on one
/// side of the other face's plane (tried both ways). `false` decides nothing: call
/// [`faces_intersect_filtered`] then.
///
/// Why that proves it (faces with distinct corner ids, sharing `k ≤ 2` of them): the face
/// whose unshared corners lie strictly on one side meets the other's plane only in its shared
/// corners (`k = 0`: nowhere; `k = 1`: the shared corner; `k = 2`: the shared edge, its
/// opposite corner being off the plane), and the other face lies in that plane, so the faces
/// meet at most there: the fast negatives of [`faces_intersect_filtered`], with the shared
/// edge case tried both ways.
///
/// With distinct ids on both sides, each face has as many corners shared with the other as
/// the other has with it, and `b` shares all three exactly when it is `a` (so `false`); the
/// mask of `a`'s shared corners is computed only when the first way fails.
#[inline]
pub fn certainly_apart(a: &PreparedFace, b: &PreparedFace) -> bool {
    if !(a.has_distinct_ids() & b.has_distinct_ids()) {
        return false;
    }
    let shared_b = b.shared_mask(a);
    if shared_b == 0b111 {
        return false;
    }
    a.others_strictly_one_side(b, shared_b) || b.others_strictly_one_side(a, a.shared_mask(b))
}

/// True if the closed fan of triangles `(apex, rim[i][0], rim[i][1])` certainly has no two faces
/// that intersect in the sense of [`faces_intersect`] (faces meet only in the apex and, for
/// neighbours, along their shared edge), so the pairwise tests can be skipped.
///
/// Precondition: the fan is the full star of a vertex of a closed 2-manifold (each rim vertex
/// ends one face's rim edge and starts the next one's), with distinct rim vertices.
///
/// The proof, with every sign certified by [`certain_orient3d`] (the answer is `false` as soon as
/// one is uncertain): project along the line from `apex` to `q = apex + Σ face normals`.
/// 1. Every face projects to a non-degenerate triangle, all of one orientation, so each face is
///    one-to-one onto its projection, a sector at the apex of angle in (0, π).
/// 2. The rim is a closed chain of such sectors, so it winds around the apex a whole number
///    `w ≥ 1` of times, and every ray from the apex (along no rim vertex) lies in exactly `w`
///    sectors. The ray towards the centroid of the first face lies in exactly one: `w = 1`.
/// 3. So the sectors tile the plane around the apex: two faces' projections meet only in the
///    apex, or along the common edge of neighbours. A common point of the faces projects there
///    and, the projection being one-to-one on each face, is the apex or on the common edge.
pub fn fan_is_embedded(apex: DVec3, rim: &[[DVec3; 2]]) -> bool {
    let normal: DVec3 = rim.iter().map(|[x, y]| (*x - apex).cross(*y - apex)).sum();
    let q = apex + normal;
    let Some(&[x0, y0]) = rim.first() else {
        return false;
    };
    let ray = (apex + x0 + y0) / 3.0;
    let Some(side) = certain_orient3d(apex, x0, y0, q) else {
        return false;
    };
    let mut sectors_on_ray = 0;
    for &[x, y] in rim {
        if certain_orient3d(apex, x, y, q) != Some(side) {
            return false;
        }
        let (Some(after_x), Some(before_y)) = (
            certain_orient3d(apex, x, ray, q),
            certain_orient3d(apex, ray, y, q),
        ) else {
            return false;
        };
        sectors_on_ray += usize::from(after_x == side && before_y == side);
    }
    sectors_on_ray == 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn collinear(p: &[DVec3], t: [u32; 3]) -> bool {
        let [a, b, c] = t.map(|i| p[i as usize]);
        (b - a).cross(c - a) == DVec3::ZERO
    }

    /// On small integer coordinates (many exact coplanar and touching configurations) and
    /// index triples sharing 0–3 indices, the filter agrees with the exact test whenever no face
    /// is collinear.
    #[test]
    fn agrees_with_the_exact_test_on_non_degenerate_faces() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut checked = 0;
        let mut hits = 0;
        for _ in 0..300 {
            let positions: Vec<DVec3> = (0..8)
                .map(|_| {
                    DVec3::new(
                        rng.random_range(-2..=2) as f64,
                        rng.random_range(-2..=2) as f64,
                        rng.random_range(-2..=2) as f64,
                    )
                })
                .collect();
            for _ in 0..50 {
                let mut pick = || {
                    let mut t = [0u32; 3];
                    loop {
                        for x in &mut t {
                            *x = rng.random_range(0..8);
                        }
                        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                            return t;
                        }
                    }
                };
                let (ta, tb) = (pick(), pick());
                if collinear(&positions, ta) || collinear(&positions, tb) {
                    continue;
                }
                let exact = faces_intersect(&positions, ta, tb);
                assert_eq!(
                    faces_intersect_filtered(&positions, ta, tb),
                    exact,
                    "{ta:?} {tb:?} {positions:?}"
                );
                checked += 1;
                hits += exact as usize;
            }
        }
        assert!(checked > 5000 && hits > 500, "{checked} pairs, {hits} hits");
    }

    /// Random triangle pairs near each other (general position, so nearly every pair is
    /// decided): whenever `certain_crossing` answers, it is the exact answer.
    #[test]
    fn certain_crossing_agrees_with_the_exact_test() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (mut decided, mut hits) = (0, 0);
        for round in 0..20_000 {
            let mut point = |r: f64| {
                DVec3::new(
                    rng.random_range(-r..r),
                    rng.random_range(-r..r),
                    rng.random_range(-r..r),
                )
            };
            // Every fourth pair on small integers: exact coplanar and touching cases.
            let (a, b) = if round % 4 == 0 {
                let mut grid = || point(2.5).round();
                ([grid(), grid(), grid()], [grid(), grid(), grid()])
            } else {
                (
                    [point(1.0), point(1.0), point(1.0)],
                    [point(1.0), point(1.0), point(1.0)],
                )
            };
            let exact = crate::spatial::triangles_intersect(a, b);
            if let Some(answer) = certain_crossing(a, b) {
                assert_eq!(answer, exact, "{a:?} {b:?}");
                decided += 1;
                hits += usize::from(exact);
            }
        }
        assert!(
            decided > 12_000 && hits > 3000,
            "{decided} decided, {hits} hits"
        );
    }

    /// A fan around the origin: `rim` points at the given angles (radians) and heights.
    fn fan(angles: &[f64], heights: &[f64]) -> Vec<[DVec3; 2]> {
        let at = |k: usize| {
            let k = k % angles.len();
            DVec3::new(angles[k].cos(), angles[k].sin(), heights[k])
        };
        (0..angles.len()).map(|k| [at(k), at(k + 1)]).collect()
    }

    #[test]
    fn flat_and_gently_curved_fans_are_embedded_but_folded_or_doubly_wound_ones_are_not() {
        let six: Vec<f64> = (0..6)
            .map(|k| k as f64 * std::f64::consts::TAU / 6.0)
            .collect();
        assert!(fan_is_embedded(DVec3::ZERO, &fan(&six, &[0.0; 6])));
        assert!(fan_is_embedded(
            DVec3::ZERO,
            &fan(&six, &[0.3, -0.2, 0.5, 0.1, -0.4, 0.2])
        ));
        // A rim point pulled across its neighbour: one face folds over.
        let mut folded = six.clone();
        folded[2] = six[0] - 0.3;
        assert!(!fan_is_embedded(DVec3::ZERO, &fan(&folded, &[0.0; 6])));
        // The rim goes around twice.
        let twice: Vec<f64> = (0..7)
            .map(|k| k as f64 * 2.0 * std::f64::consts::TAU / 7.0)
            .collect();
        assert!(!fan_is_embedded(DVec3::ZERO, &fan(&twice, &[0.0; 7])));
        assert!(!fan_is_embedded(DVec3::ZERO, &[]));
    }

    /// Random fans (flat ones with exactly representable coordinates included): whenever the
    /// fan is reported embedded, the exact test finds no intersecting pair.
    #[test]
    fn embedded_fans_have_no_intersecting_pair() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut embedded = 0;
        for trial in 0..3000 {
            let k = rng.random_range(3..9);
            let mut angles: Vec<f64> = (0..k)
                .map(|_| rng.random_range(0.0..std::f64::consts::TAU))
                .collect();
            angles.sort_by(f64::total_cmp);
            if trial % 3 == 0 {
                angles.swap(0, k / 2); // often folded
            }
            let heights: Vec<f64> = (0..k)
                .map(|_| {
                    if trial % 2 == 0 {
                        0.0
                    } else {
                        rng.random_range(-1.5..1.5)
                    }
                })
                .collect();
            let rim = fan(&angles, &heights);
            if !fan_is_embedded(DVec3::ZERO, &rim) {
                continue;
            }
            embedded += 1;
            let mut positions = vec![DVec3::ZERO];
            positions.extend(rim.iter().map(|r| r[0]));
            let face = |i: usize| [0, 1 + i as u32, 1 + ((i + 1) % k) as u32];
            for i in 0..k {
                for j in i + 1..k {
                    assert!(
                        !faces_intersect(&positions, face(i), face(j)),
                        "{angles:?} {heights:?}"
                    );
                }
            }
        }
        assert!(embedded > 500, "{embedded}");
    }

    #[test]
    fn certain_signs_are_right_and_coplanar_points_are_uncertain() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let up = certain_orient3d(a, b, c, DVec3::Z);
        let down = certain_orient3d(a, b, c, -DVec3::Z);
        assert!(up.is_some() && down.is_some() && up != down);
        assert_eq!(certain_orient3d(a, b, c, DVec3::new(0.3, 0.7, 0.0)), None);
        assert_eq!(certain_orient2d(0, 1, a, b, c), Some(1));
        assert_eq!(certain_orient2d(0, 1, a, c, b), Some(-1));
        assert_eq!(certain_orient2d(0, 1, a, b, 2.0 * b), None);
    }

    /// Coplanar fans (the flat regions where the exact predicates are slow): the filter agrees
    /// with the exact test on faces sharing the apex or an edge, and on unrelated faces.
    #[test]
    fn agrees_with_the_exact_test_on_coplanar_faces() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut decided = 0;
        for _ in 0..2000 {
            // Points on the plane z = x/2 + y/4 (exact in binary), integer x, y.
            let positions: Vec<DVec3> = (0..7)
                .map(|_| {
                    let (x, y) = (
                        rng.random_range(-4..=4) as f64,
                        rng.random_range(-4..=4) as f64,
                    );
                    DVec3::new(x, y, x / 2.0 + y / 4.0)
                })
                .collect();
            let ta = [0, 1, 2];
            let tb = [[0, 3, 4], [1, 0, 3], [4, 5, 6]][rng.random_range(0..3)];
            if collinear(&positions, ta) || collinear(&positions, tb) {
                continue;
            }
            let exact = faces_intersect(&positions, ta, tb);
            assert_eq!(faces_intersect_filtered(&positions, ta, tb), exact);
            decided += (!exact) as usize;
        }
        assert!(decided > 300);
    }

    /// The exact sign of `orient3d(a, b, c, d)` (Shewchuk's adaptive predicate).
    fn exact_orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        let c3 = |p: DVec3| robust::Coord3D {
            x: p.x,
            y: p.y,
            z: p.z,
        };
        robust::orient3d(c3(a), c3(b), c3(c), c3(d))
    }

    /// Points near a plane, far from the origin (so the differences round), with offsets from
    /// 0 to well above the error bound: every side a prepared face certifies is the exact sign
    /// of `orient3d(q, c1, c2, c0)`, and most clearly off-plane points are certified.
    #[test]
    fn prepared_sides_are_exact_signs() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        let (mut certified, mut off_plane) = (0, 0);
        for _ in 0..20_000 {
            let origin = DVec3::new(1e3, -3e2, 7e2) * rng.random_range(0.0..1.0);
            let u = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let v = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let n = u.cross(v);
            let on_plane = |rng: &mut ChaCha8Rng, offset: f64| {
                origin
                    + u * rng.random_range(-2.0..2.0)
                    + v * rng.random_range(-2.0..2.0)
                    + n * offset
            };
            let corners = [0.0, 0.0, 0.0].map(|o| on_plane(&mut rng, o));
            let face = PreparedFace::new([0, 1, 2], corners);
            let offsets = [0.0, 1e-15, -1e-13, 1e-11, -1e-6];
            let points = [0, 1, 2].map(|_| {
                let offset = offsets[rng.random_range(0..5)];
                on_plane(&mut rng, offset)
            });
            let (above, below) = face.side_masks(&points);
            assert_eq!(above & below, 0);
            for (i, &q) in points.iter().enumerate() {
                let exact = exact_orient3d(q, corners[1], corners[2], corners[0]);
                if above >> i & 1 == 1 {
                    assert!(exact > 0.0, "{q:?} {corners:?}");
                    certified += 1;
                }
                if below >> i & 1 == 1 {
                    assert!(exact < 0.0, "{q:?} {corners:?}");
                    certified += 1;
                }
                off_plane += usize::from(exact.abs() > 1e-9 * n.length());
            }
        }
        assert!(certified > off_plane / 2, "{certified} of {off_plane}");
    }

    /// `certainly_apart` computes the shared-corner masks lazily; it answers as the rule with
    /// both masks up front did (faces with repeated ids included).
    #[test]
    fn certainly_apart_answers_as_with_both_masks_up_front() {
        let reference = |a: &PreparedFace, b: &PreparedFace| {
            let (shared_a, shared_b) = (a.shared_mask(b), b.shared_mask(a));
            let valid = a.has_distinct_ids()
                & b.has_distinct_ids()
                & (shared_a.count_ones() == shared_b.count_ones())
                & (shared_b != 0b111);
            valid
                && (a.others_strictly_one_side(b, shared_b)
                    || b.others_strictly_one_side(a, shared_a))
        };
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let positions: Vec<DVec3> = (0..6)
            .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()))
            .collect();
        let mut agreed = [0usize; 2];
        for _ in 0..5000 {
            let [ta, tb] = [0, 1].map(|_| [0, 1, 2].map(|_| rng.random_range(0..6u32)));
            let prepare = |t: [u32; 3]| PreparedFace::new(t, t.map(|i| positions[i as usize]));
            let (a, b) = (prepare(ta), prepare(tb));
            let answer = certainly_apart(&a, &b);
            assert_eq!(answer, reference(&a, &b), "{ta:?} {tb:?}");
            agreed[usize::from(answer)] += 1;
        }
        assert!(agreed[0] > 100 && agreed[1] > 100, "{agreed:?}");
    }

    /// Random face pairs sharing 0–3 corner ids, on small integer coordinates (many exactly
    /// coplanar or touching configurations) and on nearly coplanar real ones: whenever
    /// `certainly_apart` answers yes, the exact test finds no intersection.
    #[test]
    fn certainly_apart_only_for_pairs_the_exact_test_finds_apart() {
        let mut rng = ChaCha8Rng::seed_from_u64(23);
        let (mut apart, mut exact_apart) = (0, 0);
        for trial in 0..600 {
            let positions: Vec<DVec3> = (0..8)
                .map(|_| {
                    let p = DVec3::new(
                        rng.random_range(-2..=2) as f64,
                        rng.random_range(-2..=2) as f64,
                        rng.random_range(-2..=2) as f64,
                    );
                    if trial % 2 == 0 {
                        p
                    } else {
                        // Nearly on the plane z = 0.3 x − 0.7 y.
                        let z = 0.3 * p.x - 0.7 * p.y + rng.random_range(-1e-14..1e-14);
                        DVec3::new(p.x + 0.1, p.y, z)
                    }
                })
                .collect();
            for _ in 0..50 {
                let mut pick = || loop {
                    let t: [u32; 3] = [0, 1, 2].map(|_| rng.random_range(0..8));
                    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                        return t;
                    }
                };
                let (ta, tb) = (pick(), pick());
                if collinear(&positions, ta) || collinear(&positions, tb) {
                    continue;
                }
                let prepare = |t: [u32; 3]| PreparedFace::new(t, t.map(|i| positions[i as usize]));
                let exact = faces_intersect(&positions, ta, tb);
                if certainly_apart(&prepare(ta), &prepare(tb)) {
                    assert!(!exact, "{ta:?} {tb:?} {positions:?}");
                    apart += 1;
                }
                exact_apart += usize::from(!exact);
            }
        }
        assert!(apart > exact_apart / 3, "{apart} of {exact_apart}");
    }
}
