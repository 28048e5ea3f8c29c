//! Garland–Heckbert quadrics and the one small dense solve behind them (nalgebra's Cholesky), for both edge-collapse
//! users: the QEM decimation ([`crate::decimate`]) and the loop's QSlim edge costs
//! ([`crate::blocks::qslim`]).

use glam::DVec3;
use nalgebra::{Matrix3, Vector3};

/// The error quadric `E(x) = xᵀ A x + 2 bᵀ x + c` of a sum of weighted squared plane distances.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Quadric {
    /// Upper triangle of the symmetric A: xx, xy, xz, yy, yz, zz.
    a: [f64; 6],
    b: DVec3,
    c: f64,
}

impl Quadric {
    /// `weight · (n·x + d)²` for the plane through `point` with unit normal `n`.
    pub fn from_plane(n: DVec3, point: DVec3, weight: f64) -> Quadric {
        let d = -n.dot(point);
        Quadric {
            a: outer(n).map(|x| x * weight),
            b: n * (d * weight),
            c: d * d * weight,
        }
    }

    /// Adds `weight · (n·x + d)²` for the plane through `point` with unit normal `n`, in place.
    /// The same quadric as `self.add(&Quadric::from_plane(n, point, weight))` but for the
    /// constant term, which is rounded as `(weight·d)·d` here and `(d·d)·weight` there: the QSlim
    /// costs and the decimation each keep their own rounding, so their outputs do not move.
    pub fn add_plane(&mut self, n: DVec3, point: DVec3, weight: f64) {
        let d = -n.dot(point);
        for (x, p) in self.a.iter_mut().zip(outer(n)) {
            *x += p * weight;
        }
        self.b += n * (weight * d);
        self.c += weight * d * d;
    }

    /// Sum of two quadrics.
    pub fn add(&self, o: &Quadric) -> Quadric {
        let mut a = self.a;
        for (x, y) in a.iter_mut().zip(o.a) {
            *x += y;
        }
        Quadric {
            a,
            b: self.b + o.b,
            c: self.c + o.c,
        }
    }

    /// `E(p)`, clamped at 0 (rounding can make it slightly negative).
    pub fn eval(&self, p: DVec3) -> f64 {
        let [xx, xy, xz, yy, yz, zz] = self.a;
        let ap = DVec3::new(
            xx * p.x + xy * p.y + xz * p.z,
            xy * p.x + yy * p.y + yz * p.z,
            xz * p.x + yz * p.y + zz * p.z,
        );
        (p.dot(ap) + 2.0 * self.b.dot(p) + self.c).max(0.0)
    }

    /// The minimiser of `E`, `x = −A⁻¹ b`, or `None` when A is (near) singular:
    /// `det A ≤ 1e-8 · trace(A)³` (flat or cylindrical neighbourhoods). A is positive
    /// semi-definite, so `det = λ₁λ₂λ₃` and `trace ≥ λ_max`: every matrix whose smallest
    /// eigenvalue is below `1e-8` times its largest is rejected.
    pub fn minimizer(&self) -> Option<DVec3> {
        let [xx, xy, xz, yy, yz, zz] = self.a;
        let trace = xx + yy + zz;
        if !(trace > 0.0 && trace.is_finite()) {
            return None;
        }
        solve_positive_definite(
            [xx, xy, xz, yy, yz, zz],
            -self.b,
            1e-8 * trace * trace * trace,
        )
    }
}

/// The solution of `A x = r` for the symmetric A with upper triangle `a` (xx, xy, xz, yy, yz,
/// zz), by nalgebra's Cholesky factorization `A = L Lᵀ`; `None` unless A is positive definite
/// with `det A = (l₀₀ l₁₁ l₂₂)² > min_det` and the solution is finite. NaN input is rejected.
fn solve_positive_definite(a: [f64; 6], r: DVec3, min_det: f64) -> Option<DVec3> {
    let [xx, xy, xz, yy, yz, zz] = a;
    let m = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let cholesky = m.cholesky()?;
    let l = cholesky.l_dirty();
    let root_det = l[(0, 0)] * l[(1, 1)] * l[(2, 2)];
    // NaN fails the comparison and is rejected too.
    let well_conditioned = root_det * root_det > min_det;
    if !well_conditioned {
        return None;
    }
    let x = cholesky.solve(&Vector3::new(r.x, r.y, r.z));
    let p = DVec3::new(x[0], x[1], x[2]);
    p.is_finite().then_some(p)
}

/// The upper triangle of `n nᵀ` (xx, xy, xz, yy, yz, zz), as a [`Quadric`] stores its A.
fn outer(n: DVec3) -> [f64; 6] {
    [
        n.x * n.x,
        n.x * n.y,
        n.x * n.z,
        n.y * n.y,
        n.y * n.z,
        n.z * n.z,
    ]
}

/// Placement and cost of merging two vertices with quadric sum `q`: the minimiser of `q` if it
/// exists and lies within `3·|pa − pb|` of the midpoint, else the best of `pa`, `pb` and the
/// midpoint.
pub fn placement(q: &Quadric, pa: DVec3, pb: DVec3) -> (DVec3, f64) {
    let mid = 0.5 * (pa + pb);
    if let Some(p) = q.minimizer()
        && p.distance(mid) <= 3.0 * pa.distance(pb)
    {
        return (p, q.eval(p));
    }
    [mid, pa, pb]
        .into_iter()
        .map(|p| (p, q.eval(p)))
        .fold(
            (mid, f64::INFINITY),
            |best, c| if c.1 < best.1 { c } else { best },
        )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_planes_meet_at_their_corner() {
        let corner = DVec3::new(0.3, -0.2, 0.7);
        let q = Quadric::from_plane(DVec3::X, corner, 1.0)
            .add(&Quadric::from_plane(DVec3::Y, corner, 2.0))
            .add(&Quadric::from_plane(DVec3::Z, corner, 0.5));
        let p = q.minimizer().expect("regular");
        assert!(p.distance(corner) < 1e-12);
        assert!(q.eval(p) < 1e-20);
        assert!((q.eval(corner + DVec3::X) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn minimizer_solves_the_normal_equations_of_tilted_planes() {
        // Three tilted planes with unequal weights plus a fourth: a full, non-diagonal A.
        let planes = [
            (DVec3::new(1.0, 0.2, -0.1), DVec3::new(0.1, 0.0, 0.3), 1.0),
            (DVec3::new(-0.3, 1.0, 0.4), DVec3::new(0.0, -0.2, 0.1), 2.5),
            (DVec3::new(0.2, 0.1, 1.0), DVec3::new(0.4, 0.1, -0.3), 0.7),
            (DVec3::new(1.0, 1.0, 1.0), DVec3::new(0.2, 0.2, 0.2), 0.3),
        ];
        let q = planes.iter().fold(Quadric::default(), |q, &(n, p, w)| {
            q.add(&Quadric::from_plane(n.normalize(), p, w))
        });
        let x = q.minimizer().expect("regular");
        // The gradient 2(Ax + b) vanishes at the minimiser, and E grows in every direction.
        let [xx, xy, xz, yy, yz, zz] = q.a;
        let ax = DVec3::new(
            xx * x.x + xy * x.y + xz * x.z,
            xy * x.x + yy * x.y + yz * x.z,
            xz * x.x + yz * x.y + zz * x.z,
        );
        assert!(
            (ax + q.b).length() < 1e-12,
            "residual {}",
            (ax + q.b).length()
        );
        for d in [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE] {
            assert!(q.eval(x + 1e-3 * d) > q.eval(x));
            assert!(q.eval(x - 1e-3 * d) > q.eval(x));
        }
    }

    #[test]
    fn two_planes_and_non_finite_quadrics_have_no_minimizer() {
        let q = Quadric::from_plane(DVec3::X, DVec3::ZERO, 1.0).add(&Quadric::from_plane(
            DVec3::Y,
            DVec3::ONE,
            1.0,
        ));
        assert!(q.minimizer().is_none());
        let nan = Quadric::from_plane(DVec3::new(f64::NAN, 0.0, 1.0), DVec3::ZERO, 1.0)
            .add(&Quadric::from_plane(DVec3::X, DVec3::ZERO, 1.0))
            .add(&Quadric::from_plane(DVec3::Y, DVec3::ZERO, 1.0));
        assert!(nan.minimizer().is_none());
        // A regular quadric whose smallest eigenvalue is 1e-10 of its largest is rejected too.
        let thin = Quadric::from_plane(DVec3::X, DVec3::ZERO, 1.0)
            .add(&Quadric::from_plane(DVec3::Y, DVec3::ZERO, 1.0))
            .add(&Quadric::from_plane(DVec3::Z, DVec3::ZERO, 1e-10));
        assert!(thin.minimizer().is_none());
    }

    #[test]
    fn one_plane_is_singular_and_falls_back_to_the_best_candidate() {
        let q = Quadric::from_plane(DVec3::Z, DVec3::ZERO, 1.0);
        assert!(q.minimizer().is_none());
        let (p, cost) = placement(&q, DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(p, DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(cost, 0.0);
    }
}
