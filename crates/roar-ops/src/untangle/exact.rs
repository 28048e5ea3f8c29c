//! A non-allocating front end to the exact face–face test, with floating-point filters that
//! settle the common adjacent-face cases without the exact predicates.
//!
//! [`faces_cross`] gives the same answer as [`faces_intersect`] (it falls back to it whenever a
//! filter is not certain): it only adds shortcuts that are provably correct. A filtered
//! `orient3d` uses Shewchuk's static error bound (`o3derrboundA`), so a sign it reports is the
//! exact sign.

use glam::DVec3;
use roar_mesh::spatial::{faces_intersect, triangles_intersect};

/// Shewchuk's `o3derrboundA = (7 + 56ε)ε` with ε = 2⁻⁵³.
const O3D_ERRBOUND_A: f64 = (7.0 + 56.0 * f64::EPSILON / 2.0) * f64::EPSILON / 2.0;

/// Sign of the orientation of `d` relative to the plane `abc` when the floating-point
/// evaluation is certain (`Some(±1)`), `None` when it is too close to call.
#[inline]
pub(crate) fn orient3d_filtered(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<i8> {
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
    let bound = O3D_ERRBOUND_A * permanent;
    if det > bound {
        Some(1)
    } else if det < -bound {
        Some(-1)
    } else {
        None
    }
}

/// Both `p` and `q` are certainly strictly on the same side of the plane `abc`.
#[inline]
fn same_strict_side(plane: [DVec3; 3], p: DVec3, q: DVec3) -> bool {
    let [a, b, c] = plane;
    match (orient3d_filtered(a, b, c, p), orient3d_filtered(a, b, c, q)) {
        (Some(x), Some(y)) => x == y,
        _ => false,
    }
}

/// Exactly [`faces_intersect`]`(positions, ta, tb)`, without allocating, and with fast answers
/// for the adjacent cases a mesh is full of:
/// - sharing an edge `uv`: the faces can only overlap if coplanar, so a certain non-zero
///   `orient3d(u, v, a, b)` means no intersection;
/// - sharing one corner `s`: if the other two corners of one face are certainly strictly on one
///   side of the other face's plane, that face meets the plane only at `s`, so the contact is
///   the shared vertex alone.
///
/// Callers must pass valid indices (in range); degenerate faces fall through to the exact test.
pub(crate) fn faces_cross(positions: &[DVec3], ta: [u32; 3], tb: [u32; 3]) -> bool {
    let mut shared = 0usize;
    let mut ia = [0usize; 3];
    let mut ib = [0usize; 3];
    for i in 0..3 {
        for j in 0..3 {
            if ta[i] == tb[j] {
                ia[shared] = i;
                ib[shared] = j;
                shared += 1;
            }
        }
    }
    let n = positions.len();
    if ta.iter().chain(&tb).any(|&i| i as usize >= n) {
        return false;
    }
    let pa = ta.map(|i| positions[i as usize]);
    let pb = tb.map(|i| positions[i as usize]);
    match shared {
        0 => {
            let degenerate = |t: [u32; 3]| t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
            if degenerate(ta) || degenerate(tb) {
                return false;
            }
            triangles_intersect(pa, pb)
        }
        1 => {
            let (i, j) = (ia[0], ib[0]);
            if same_strict_side(pa, pb[(j + 1) % 3], pb[(j + 2) % 3])
                || same_strict_side(pb, pa[(i + 1) % 3], pa[(i + 2) % 3])
            {
                return false;
            }
            faces_intersect(positions, ta, tb)
        }
        2 => {
            let u = pa[ia[0]];
            let v = pa[ia[1]];
            let a = pa[3 - ia[0] - ia[1]];
            let b = pb[3 - ib[0] - ib[1]];
            if orient3d_filtered(u, v, a, b).is_some() {
                return false;
            }
            faces_intersect(positions, ta, tb)
        }
        _ => faces_intersect(positions, ta, tb),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn filtered_orientation_agrees_with_the_sign_of_the_volume() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let up = orient3d_filtered(a, b, c, DVec3::Z).unwrap();
        let down = orient3d_filtered(a, b, c, -DVec3::Z).unwrap();
        assert_eq!(up, -down);
        assert_eq!(orient3d_filtered(a, b, c, DVec3::new(0.3, 0.3, 0.0)), None);
    }

    /// Brute-force check against the exact test on small random meshes with shared indices,
    /// including exactly coplanar configurations (integer grid coordinates).
    #[test]
    fn faces_cross_matches_faces_intersect() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut disagreements = 0;
        let mut hits = 0;
        for _ in 0..20_000 {
            let grid = rng.random_bool(0.5);
            let positions: Vec<DVec3> = (0..6)
                .map(|_| {
                    let mut p = DVec3::new(
                        rng.random_range(-2.0..2.0),
                        rng.random_range(-2.0..2.0),
                        rng.random_range(-2.0..2.0),
                    );
                    if grid {
                        p = p.round();
                        p.z = if rng.random_bool(0.7) { 0.0 } else { p.z };
                    }
                    p
                })
                .collect();
            let mut pick = || -> [u32; 3] {
                loop {
                    let t = [0, 0, 0].map(|_: u32| rng.random_range(0..6u32));
                    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                        return t;
                    }
                }
            };
            let (ta, tb) = (pick(), pick());
            let exact = faces_intersect(&positions, ta, tb);
            hits += usize::from(exact);
            if faces_cross(&positions, ta, tb) != exact {
                disagreements += 1;
            }
        }
        assert_eq!(disagreements, 0);
        assert!(
            hits > 1000,
            "the sample must contain intersecting pairs: {hits}"
        );
    }
}
