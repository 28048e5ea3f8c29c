//! Fairing of the vertices no data holds: the surface a soup's holes leave to the loop is filled
//! with the smoothest continuation of the surface around it, not the membrane the loop makes.
//!
//! Over a hole the loop's losses pull nothing into place and its Laplacian term, a membrane,
//! flattens the cap, so a cap across a curved part sits below the surface it replaces. Here the
//! vertices marked free are moved to minimize the thin-plate energy `Σ_v |(L x)_v|²` over every
//! vertex `v`, with `L` the row-normalized cotangent Laplacian and every other vertex fixed; the
//! minimizer continues the curvature of the fixed ring into the cap (Botsch and Kobbelt 2004).

use glam::DVec3;
use roar_mesh::Mesh;

use crate::finish::zero_set::limited_step;
use crate::geometry::mean_edge_length;

/// The default distance, over a vertex's mean edge length, beyond which [`vertices_far_from`]
/// marks it: on the tuning punctured inputs 0.3 leaves the outputs from the closed originals
/// unchanged and raises the caps (docs/method.md#finish).
pub const FAIR_DISTANCE_OVER_EDGE: f64 = 0.3;

/// Per vertex of `mesh` (compacted; indexed as `mesh.to_triangles` numbers them), whether it
/// lies farther from the surface than `distance_over_edge` times its mean edge length (what no
/// data holds); `near(p, r)` says whether the surface comes within `r` of `p`.
pub fn vertices_far_from(
    mesh: &mut Mesh,
    near: impl Fn(DVec3, f64) -> bool,
    distance_over_edge: f64,
) -> Vec<bool> {
    mesh.compact();
    mesh.vertices()
        .map(|v| {
            mean_edge_length(mesh, v)
                .is_some_and(|edge| !near(mesh.position(v), distance_over_edge * edge))
        })
        .collect()
}

/// Options of [`fair_free_vertices`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FairOptions {
    /// Conjugate-gradient iterations of the thin-plate solve (it stops earlier once the residual
    /// falls by `1e-8`).
    pub iterations: usize,
    /// Limited steps toward the faired positions: each move at most `max_move_fraction` of the
    /// vertex's smallest height, shortened where faces would intersect.
    pub steps: usize,
    /// See `steps`.
    pub max_move_fraction: f64,
}

impl Default for FairOptions {
    fn default() -> Self {
        Self {
            iterations: 500,
            steps: 4,
            max_move_fraction: 0.5,
        }
    }
}

/// What [`fair_free_vertices`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FairStats {
    /// Vertices marked free.
    pub free: usize,
    /// Free vertices that reached their faired position (the others were moved part of the way
    /// or not at all: a move that would fold a face or make faces intersect).
    pub faired: usize,
}

/// Moves the vertices with `free[v]` (one flag per vertex, indexed as `mesh.to_triangles`
/// numbers them after `mesh.compact()`, as [`vertices_far_from`] gives them) to the positions
/// minimizing the thin-plate energy with the others fixed, through `options.steps` limited steps
/// (as `fit_to_zero_set` moves). The topology stays; the mesh stays free of self-intersections
/// when it was. Panics when `free` has another length than the mesh has vertices.
pub fn fair_free_vertices(mesh: &mut Mesh, free: &[bool], options: &FairOptions) -> FairStats {
    mesh.compact();
    let (start, triangles) = mesh.to_triangles();
    assert_eq!(free.len(), start.len(), "one flag per vertex");
    let count = free.iter().filter(|&&f| f).count();
    if count == 0 {
        return FairStats::default();
    }
    let laplacian = Laplacian::cotangent(&start, &triangles);
    let target = thin_plate(&laplacian, &start, free, options.iterations);
    let mut positions = start.clone();
    for _ in 0..options.steps {
        positions = limited_step(&positions, &target, &triangles, options.max_move_fraction);
    }
    let faired = (0..start.len())
        .filter(|&v| free[v] && positions[v] == target[v])
        .count();
    mesh.positions_mut().copy_from_slice(&positions);
    FairStats {
        free: count,
        faired,
    }
}

/// `L = I − W` with `W` row-stochastic: each row the cotangent weights of the vertex's edges
/// (negative ones clamped to 0), normalized; uniform weights where all are 0.
struct Laplacian {
    /// Per vertex, its neighbours with their normalized weights.
    rows: Vec<Vec<(usize, f64)>>,
}

impl Laplacian {
    fn cotangent(positions: &[DVec3], triangles: &[[u32; 3]]) -> Self {
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); positions.len()];
        for t in triangles {
            for k in 0..3 {
                let (o, a, b) = (
                    t[k] as usize,
                    t[(k + 1) % 3] as usize,
                    t[(k + 2) % 3] as usize,
                );
                let (u, v) = (positions[a] - positions[o], positions[b] - positions[o]);
                let cross = u.cross(v).length();
                let cot = if cross > 0.0 { u.dot(v) / cross } else { 0.0 };
                let w = 0.5 * cot.max(0.0);
                rows[a].push((b, w));
                rows[b].push((a, w));
            }
        }
        for row in &mut rows {
            row.sort_by_key(|&(j, _)| j);
            row.dedup_by(|next, kept| {
                let same = next.0 == kept.0;
                if same {
                    kept.1 += next.1;
                }
                same
            });
            let sum: f64 = row.iter().map(|&(_, w)| w).sum();
            let n = row.len() as f64;
            for entry in row.iter_mut() {
                entry.1 = if sum > 0.0 { entry.1 / sum } else { 1.0 / n };
            }
        }
        Self { rows }
    }

    /// `L x`.
    fn apply(&self, x: &[DVec3]) -> Vec<DVec3> {
        self.rows
            .iter()
            .enumerate()
            .map(|(i, row)| x[i] - row.iter().map(|&(j, w)| w * x[j]).sum::<DVec3>())
            .collect()
    }

    /// `Lᵀ y`.
    fn apply_transposed(&self, y: &[DVec3]) -> Vec<DVec3> {
        let mut out = y.to_vec();
        for (i, row) in self.rows.iter().enumerate() {
            for &(j, w) in row {
                out[j] -= w * y[i];
            }
        }
        out
    }
}

/// The positions minimizing `|L x|²` over the free vertices, the others at `start`: conjugate
/// gradients on `(LᵀL)_ff x_f = −(LᵀL)_fc x_c`, each coordinate its own solve (componentwise
/// arithmetic), from `start`.
fn thin_plate(
    laplacian: &Laplacian,
    start: &[DVec3],
    free: &[bool],
    iterations: usize,
) -> Vec<DVec3> {
    let restrict = |mut v: Vec<DVec3>| {
        for (x, &f) in v.iter_mut().zip(free) {
            if !f {
                *x = DVec3::ZERO;
            }
        }
        v
    };
    let normal = |x: &[DVec3]| laplacian.apply_transposed(&laplacian.apply(x));
    let dot = |a: &[DVec3], b: &[DVec3]| a.iter().zip(b).map(|(x, y)| *x * *y).sum::<DVec3>();
    let mut x = start.to_vec();
    let mut r: Vec<DVec3> = restrict(normal(&x)).iter().map(|g| -*g).collect();
    let mut p = r.clone();
    let mut rr = dot(&r, &r);
    let stop = rr * 1e-16;
    for _ in 0..iterations {
        if rr.cmple(stop).all() {
            break;
        }
        let ap = restrict(normal(&p));
        let pap = dot(&p, &ap);
        let alpha = DVec3::select(pap.cmpgt(DVec3::ZERO), rr / pap, DVec3::ZERO);
        for i in 0..x.len() {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        let next = dot(&r, &r);
        let beta = DVec3::select(rr.cmpgt(DVec3::ZERO), next / rr, DVec3::ZERO);
        for i in 0..p.len() {
            p[i] = r[i] + beta * p[i];
        }
        rr = next;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::{TriangleBvh, self_intersecting_faces};

    /// An icosphere with the vertices above `height` pushed down onto the plane `z = height`:
    /// a sunken cap over a curved surface, the free vertices those of the cap.
    fn sunken_cap(height: f64) -> (Mesh, Vec<bool>, Vec<DVec3>) {
        let mut mesh = icosphere(3);
        mesh.compact();
        let (sphere, _) = mesh.to_triangles();
        let free: Vec<bool> = sphere.iter().map(|p| p.z > height).collect();
        for (p, &f) in mesh.positions_mut().iter_mut().zip(&free) {
            if f {
                p.z = height;
            }
        }
        (mesh, free, sphere)
    }

    /// `|L x|²`.
    fn thin_plate_energy(laplacian: &Laplacian, x: &[DVec3]) -> f64 {
        laplacian.apply(x).iter().map(|v| v.length_squared()).sum()
    }

    fn mean_radius_error(mesh: &Mesh, free: &[bool]) -> f64 {
        let (positions, _) = mesh.to_triangles();
        let errors: Vec<f64> = positions
            .iter()
            .zip(free)
            .filter(|(_, f)| **f)
            .map(|(p, _)| (p.length() - 1.0).abs())
            .collect();
        errors.iter().sum::<f64>() / errors.len() as f64
    }

    #[test]
    fn a_flattened_cap_of_a_sphere_is_raised_back_toward_the_sphere() {
        let (mut mesh, free, _) = sunken_cap(0.8);
        let before = mean_radius_error(&mesh, &free);
        let stats = fair_free_vertices(&mut mesh, &free, &FairOptions::default());
        let after = mean_radius_error(&mesh, &free);
        assert_eq!(stats.free, free.iter().filter(|&&f| f).count());
        assert!(stats.faired > 0, "{stats:?}");
        assert!(
            after < 0.3 * before,
            "mean radius error {before} -> {after}"
        );
        mesh.validate().unwrap();
    }

    #[test]
    fn fixed_vertices_stay_and_no_face_starts_to_intersect() {
        let (mut mesh, free, _) = sunken_cap(0.5);
        let (before, triangles) = mesh.to_triangles();
        fair_free_vertices(&mut mesh, &free, &FairOptions::default());
        let (after, after_triangles) = mesh.to_triangles();
        assert_eq!(triangles, after_triangles);
        for ((a, b), f) in before.iter().zip(&after).zip(&free) {
            if !f {
                assert_eq!(a, b);
            }
        }
        assert!(!self_intersecting_faces(&after, &after_triangles).contains(&true));
    }

    #[test]
    fn a_surface_already_fair_barely_moves() {
        // The exact sphere's cap is near the thin-plate minimizer already: fairing moves it by
        // a small fraction of what it raises a flattened cap.
        let mut mesh = icosphere(3);
        mesh.compact();
        let (sphere, _) = mesh.to_triangles();
        let free: Vec<bool> = sphere.iter().map(|p| p.z > 0.8).collect();
        fair_free_vertices(&mut mesh, &free, &FairOptions::default());
        let moved = mean_radius_error(&mesh, &free);
        let (mut flat, flat_free, _) = sunken_cap(0.8);
        let sunken = mean_radius_error(&flat, &flat_free);
        fair_free_vertices(&mut flat, &flat_free, &FairOptions::default());
        assert!(moved < 0.15 * sunken, "{moved} vs {sunken}");
    }

    #[test]
    fn the_solve_minimizes_the_thin_plate_energy() {
        // Its gradient 2 LᵀL x vanishes on the free vertices, and moving any free vertex by a
        // small step in any axis raises the energy |L x|²: checks L, Lᵀ and the solve together.
        let (mesh, free, _) = sunken_cap(0.5);
        let (start, triangles) = mesh.to_triangles();
        let laplacian = Laplacian::cotangent(&start, &triangles);
        let x = thin_plate(&laplacian, &start, &free, 500);
        let energy = |x: &[DVec3]| thin_plate_energy(&laplacian, x);
        let e0 = energy(&x);
        for v in (0..x.len()).filter(|&v| free[v]).step_by(7) {
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                for h in [1e-3, -1e-3] {
                    let mut y = x.clone();
                    y[v] += h * axis;
                    assert!(energy(&y) > e0, "vertex {v}: {} <= {e0}", energy(&y));
                }
            }
        }
        let gradient = laplacian.apply_transposed(&laplacian.apply(&x));
        let largest = (0..x.len())
            .filter(|&v| free[v])
            .map(|v| gradient[v].length())
            .fold(0.0, f64::max);
        assert!(largest < 1e-9, "{largest}");
        for v in (0..x.len()).filter(|&v| !free[v]) {
            assert_eq!(x[v], start[v]);
        }
    }

    #[test]
    fn the_energy_gradient_matches_finite_differences() {
        // The solve's gradient of |L x|² is 2 LᵀL x.
        let (mesh, _, _) = sunken_cap(0.5);
        let (x, triangles) = mesh.to_triangles();
        let laplacian = Laplacian::cotangent(&x, &triangles);
        let energy = |x: &[DVec3]| thin_plate_energy(&laplacian, x);
        let gradient = laplacian.apply_transposed(&laplacian.apply(&x));
        let h = 1e-6;
        for v in (0..x.len()).step_by(5) {
            for (k, axis) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
                let (mut up, mut down) = (x.clone(), x.clone());
                up[v] += h * axis;
                down[v] -= h * axis;
                let fd = (energy(&up) - energy(&down)) / (2.0 * h);
                let analytic = 2.0 * gradient[v][k];
                assert!(
                    (fd - analytic).abs() < 1e-6,
                    "vertex {v} axis {k}: {fd} vs {analytic}"
                );
            }
        }
    }

    #[test]
    fn only_vertices_away_from_the_surface_are_marked() {
        // The surface: the sphere below z = 0.5; the mesh: the sphere with its cap sunk to that
        // plane. Marked: the cap's inner vertices, not those on the kept part.
        let (mut mesh, cap, sphere) = sunken_cap(0.5);
        let (_, triangles) = mesh.to_triangles();
        let kept: Vec<[u32; 3]> = triangles
            .iter()
            .copied()
            .filter(|t| t.iter().all(|&v| sphere[v as usize].z <= 0.5))
            .collect();
        let bvh = TriangleBvh::build(&sphere, &kept);
        let near = |p, r| bvh.closest_point_within(p, r).is_some();
        let marked = vertices_far_from(&mut mesh, near, 0.3);
        assert!(marked.iter().any(|&m| m));
        for (v, &m) in marked.iter().enumerate() {
            if m {
                assert!(cap[v], "vertex {v} on the kept part marked");
            }
        }
        let (positions, _) = mesh.to_triangles();
        let centre = (0..positions.len()).max_by(|&a, &b| sphere[a].z.total_cmp(&sphere[b].z));
        assert!(marked[centre.unwrap()], "the cap's middle is not marked");
    }

    #[test]
    fn nothing_free_changes_nothing() {
        let mut mesh = icosphere(2);
        mesh.compact();
        let (before, _) = mesh.to_triangles();
        let stats = fair_free_vertices(
            &mut mesh,
            &vec![false; before.len()],
            &FairOptions::default(),
        );
        assert_eq!(stats, FairStats::default());
        assert_eq!(mesh.to_triangles().0, before);
    }
}
