//! The last step of an SDF input's finish: the mesh fitted to the field's zero set, every vertex
//! moved along its normal as far as it can go without folding or crossing a face.

use glam::DVec3;
use roar_mesh::Mesh;
use roar_mesh::spatial::{
    Sdf, area_weighted_vertex_normals, first_order_distances, triangle_normal, triangle_quality,
};

use crate::geometry::{DEGENERATE_QUALITY, is_degenerate};
use crate::untangle::{LimiterOptions, limit_steps};

/// Options of [`fit_to_zero_set`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroSetOptions {
    /// Fitting steps (each evaluates the field's gradient at every edge midpoint).
    pub steps: usize,
    /// ε of the first-order distance `f/(|∇f| + ε)`.
    pub epsilon: f64,
    /// A vertex moves at most this fraction of its smallest height in an incident face (its
    /// distance to the opposite edge): a longer move could reach another sheet of the surface
    /// or fold a face.
    pub max_move_fraction: f64,
}

impl Default for ZeroSetOptions {
    fn default() -> Self {
        Self {
            steps: 3,
            epsilon: 1e-10,
            max_move_fraction: 0.5,
        }
    }
}

/// What [`fit_to_zero_set`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ZeroSetStats {
    /// Vertices moved the whole fitted way.
    pub fitted: usize,
    /// Vertices moved part of the way: a move too long for their faces, or one that would make
    /// faces intersect.
    pub shortened: usize,
    /// Vertices left where they were: a move that would turn a face over, make it degenerate or make faces
    /// intersect however short, or none to make.
    pub unmoved: usize,
}

/// Fits `mesh` to the zero set of `sdf`: `options.steps` times, every vertex moves along its
/// normal by minus the mean first-order distance `f/|∇f|` over its faces (area-weighted, each
/// face's mean taken at its edge midpoints, the quadrature exact for a distance quadratic over
/// the face), each move shortened to `max_move_fraction` of the vertex's smallest height,
/// shortened or cancelled where it would make faces intersect (`limit_steps`) and undone where
/// it would turn a face over (its normal against the one before the step) or make it
/// degenerate, the limiter
/// checking the positions again after each undoing. The topology stays; the mesh stays free of
/// self-intersections when it was.
///
/// Why: the loop's mesh sits on the surface only as far as the render, planar and SDF losses
/// pull it, and the fill splits that bring it to a large budget put their new vertices on the
/// old edges' chords. On a field the surface is known everywhere. Each face is fitted, not each
/// vertex: vertices on the zero set would put the faces of a curved part inside it (the chords
/// of a sphere), which at 5,000 faces costs more than it gains. Each step is limited against
/// the faces as they are, so a vertex held by a small face in one step can go on once its
/// neighbours have moved.
pub fn fit_to_zero_set(mesh: &mut Mesh, sdf: &dyn Sdf, options: &ZeroSetOptions) -> ZeroSetStats {
    // Compact, the mesh's vertex, edge and face ids are dense, and the vertex ids are the
    // indices of `to_triangles`.
    mesh.compact();
    let (start, triangles) = mesh.to_triangles();
    let mut positions = start.clone();
    let mut held = vec![false; positions.len()];
    for _ in 0..options.steps {
        let offsets = mean_distances(mesh, &positions, sdf, options.epsilon);
        let normals = area_weighted_vertex_normals(&positions, &triangles);
        let wanted: Vec<DVec3> = positions
            .iter()
            .zip(&normals)
            .zip(&offsets)
            .map(|((p, n), d)| *p - *n * *d)
            .collect();
        let moved = limited_step(&positions, &wanted, &triangles, options.max_move_fraction);
        for ((h, m), w) in held.iter_mut().zip(&moved).zip(&wanted) {
            *h |= m != w;
        }
        positions = moved;
    }

    let unmoved = positions.iter().zip(&start).filter(|(a, b)| a == b).count();
    let fitted = positions
        .iter()
        .zip(&start)
        .zip(&held)
        .filter(|((a, b), h)| a != b && !**h)
        .count();
    mesh.positions_mut().copy_from_slice(&positions);
    ZeroSetStats {
        fitted,
        shortened: positions.len() - fitted - unmoved,
        unmoved,
    }
}

/// The positions `wanted` from `positions` (an intersection-free mesh of `triangles`) allows:
/// each move shortened to `max_move_fraction` of the vertex's smallest height, then shortened
/// or cancelled where faces would intersect, and undone where a face would turn over or
/// become degenerate.
pub(crate) fn limited_step(
    positions: &[DVec3],
    wanted: &[DVec3],
    triangles: &[[u32; 3]],
    max_move_fraction: f64,
) -> Vec<DVec3> {
    let heights = smallest_heights(positions, triangles);
    let mut targets = wanted.to_vec();
    for ((target, &old), &height) in targets.iter_mut().zip(positions).zip(&heights) {
        let length = (*target - old).length();
        let longest = max_move_fraction * height;
        if !length.is_finite() {
            *target = old;
        } else if length > longest {
            *target = old + (*target - old) * (longest / length);
        }
    }
    // Each round that undoes a move leaves one more vertex where it was (the limiter never
    // moves a vertex past its target), so the loop ends.
    loop {
        let mut moved = targets.clone();
        limit_steps(positions, &mut moved, triangles, &LimiterOptions::default());
        if !undo_bad_faces(positions, &mut moved, triangles) {
            return moved;
        }
        targets = moved;
    }
}

/// Per vertex of the compact `mesh` at `positions`, the area-weighted mean over its faces of
/// the first-order distance `f/|∇f|` averaged at each face's edge midpoints (0 for a vertex in
/// no face).
fn mean_distances(mesh: &Mesh, positions: &[DVec3], sdf: &dyn Sdf, epsilon: f64) -> Vec<f64> {
    let midpoints: Vec<DVec3> = mesh
        .edges()
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            0.5 * (positions[a.index()] + positions[b.index()])
        })
        .collect();
    let distances = first_order_distances(sdf, &midpoints, epsilon);
    let mut sums = vec![(0.0, 0.0); positions.len()];
    for f in mesh.faces() {
        let corners = mesh.face_vertices(f);
        let p = corners.map(|v| positions[v.index()]);
        let area = (p[1] - p[0]).cross(p[2] - p[0]).length();
        let distance = mesh
            .face_halfedges(f)
            .iter()
            .map(|&h| distances[mesh.edge(h).index()])
            .sum::<f64>()
            / 3.0;
        for v in corners {
            let (weighted, weight) = &mut sums[v.index()];
            *weighted += area * distance;
            *weight += area;
        }
    }
    sums.into_iter()
        .map(|(weighted, weight)| {
            if weight > 0.0 && weighted.is_finite() {
                weighted / weight
            } else {
                0.0
            }
        })
        .collect()
}

/// Per vertex, its smallest distance to the opposite edge over its faces (`∞` for a vertex in
/// no face).
fn smallest_heights(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<f64> {
    let mut heights = vec![f64::INFINITY; positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        let double_area = (p[1] - p[0]).cross(p[2] - p[0]).length();
        for k in 0..3 {
            let opposite = (p[(k + 2) % 3] - p[(k + 1) % 3]).length();
            let height = if opposite > 0.0 {
                double_area / opposite
            } else {
                0.0
            };
            let h = &mut heights[t[k] as usize];
            *h = h.min(height);
        }
    }
    heights
}

/// Puts back the corners of every face whose normal turned by more than 90° or that became
/// degenerate (aspect ratio at or above [`DEGENERATE_QUALITY`]) until none does (each round puts
/// back at least one vertex, so it ends); returns whether it put any back.
fn undo_bad_faces(before: &[DVec3], moved: &mut [DVec3], triangles: &[[u32; 3]]) -> bool {
    let mut any = false;
    loop {
        let mut undone = 0;
        for t in triangles {
            let [a, b, c] = t.map(|i| i as usize);
            let old = [before[a], before[b], before[c]];
            let new = [moved[a], moved[b], moved[c]];
            let turned = triangle_normal(old[0], old[1], old[2])
                .dot(triangle_normal(new[0], new[1], new[2]))
                <= 0.0;
            let degenerated = is_degenerate(triangle_quality(new), DEGENERATE_QUALITY)
                && !is_degenerate(triangle_quality(old), DEGENERATE_QUALITY);
            if turned || degenerated {
                for i in [a, b, c] {
                    if moved[i] != before[i] {
                        moved[i] = before[i];
                        undone += 1;
                    }
                }
            }
        }
        if undone == 0 {
            return any;
        }
        any = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::{FnSdf, self_intersecting_faces};

    #[test]
    fn an_icosphere_is_fitted_to_the_sphere_of_its_field() {
        // The icosphere's vertices are on the unit sphere and its faces inside it. Scaled to
        // radius 0.98 it lies inside the field's zero set by 0.02 and more; fitted, its faces
        // straddle the sphere: the vertices end just outside it, the edge midpoints just inside.
        let mut mesh = icosphere(3);
        for p in mesh.positions_mut() {
            *p *= 0.98;
        }
        let sphere = FnSdf::new(|p: DVec3| p.length() - 1.0);
        let stats = fit_to_zero_set(&mut mesh, &sphere, &ZeroSetOptions::default());
        assert_eq!(stats.fitted, mesh.n_vertices());
        for p in mesh.positions() {
            assert!(p.length() > 1.0 && p.length() < 1.005, "{}", p.length());
        }
        let left = mean_distances(&mesh, mesh.positions(), &sphere, 1e-10);
        for d in left {
            assert!(d.abs() < 1e-4, "{d}");
        }
        mesh.validate().unwrap();
    }

    #[test]
    fn a_move_long_against_the_faces_is_shortened() {
        // Radius 0.5 against a unit-sphere field: every move (0.5) is longer than half of the
        // smallest heights of a level-2 icosphere's faces, so one step goes only that far.
        let mut mesh = icosphere(2);
        for p in mesh.positions_mut() {
            *p *= 0.5;
        }
        let (before, triangles) = mesh.to_triangles();
        let heights = smallest_heights(&before, &triangles);
        let sphere = FnSdf::new(|p: DVec3| p.length() - 1.0);
        let one_step = ZeroSetOptions {
            steps: 1,
            ..ZeroSetOptions::default()
        };
        let stats = fit_to_zero_set(&mut mesh, &sphere, &one_step);
        assert_eq!(stats.shortened, mesh.n_vertices());
        for ((p, old), height) in mesh.positions().iter().zip(&before).zip(&heights) {
            assert!(p.length() > old.length());
            let moved = (*p - *old).length();
            assert!((moved - 0.5 * height).abs() < 1e-9, "{moved} {height}");
        }
        mesh.validate().unwrap();
    }

    #[test]
    fn each_step_is_limited_against_the_faces_as_they_are() {
        // The same sphere with three steps: the faces grow as the vertices move out, so each
        // step may go farther than the one before, and the mesh ends closer to the zero set
        // than one step's half height allows.
        let mut mesh = icosphere(2);
        for p in mesh.positions_mut() {
            *p *= 0.5;
        }
        let (before, triangles) = mesh.to_triangles();
        let heights = smallest_heights(&before, &triangles);
        let sphere = FnSdf::new(|p: DVec3| p.length() - 1.0);
        fit_to_zero_set(&mut mesh, &sphere, &ZeroSetOptions::default());
        for ((p, old), height) in mesh.positions().iter().zip(&before).zip(&heights) {
            let moved = (*p - *old).length();
            assert!(moved > 1.5 * 0.5 * height, "{moved} {height}");
            assert!(p.length() < 1.0);
        }
        mesh.validate().unwrap();
    }

    #[test]
    fn no_move_makes_faces_intersect_or_turn_over() {
        // Two nested spheres, triangulated differently and turned, whose field pulls both onto one sheet
        // between them: the moves would make them cross, so some are shortened or undone, and
        // the result stays free of intersections.
        let (mut positions, mut triangles) = icosphere(2).to_triangles();
        let n = positions.len() as u32;
        let (inner, inner_triangles) = icosphere(1).to_triangles();
        let turn = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.3);
        let inner: Vec<DVec3> = inner.iter().map(|&p| 0.96 * (turn * p)).collect();
        let inner_triangles: Vec<[u32; 3]> =
            inner_triangles.iter().map(|t| t.map(|i| i + n)).collect();
        positions.extend(inner);
        triangles.extend(inner_triangles);
        let mut mesh = Mesh::from_triangles(positions, &triangles).unwrap();
        let sphere = FnSdf::new(|p: DVec3| p.length() - 0.98);
        let before = mesh.clone();
        let stats = fit_to_zero_set(&mut mesh, &sphere, &ZeroSetOptions::default());
        assert!(stats.shortened + stats.unmoved > 0, "{stats:?}");
        let (positions, triangles) = mesh.to_triangles();
        assert!(!self_intersecting_faces(&positions, &triangles).contains(&true));
        let (old, _) = before.to_triangles();
        for t in &triangles {
            let [a, b, c] = t.map(|i| i as usize);
            let n_old = triangle_normal(old[a], old[b], old[c]);
            let n_new = triangle_normal(positions[a], positions[b], positions[c]);
            assert!(n_old.dot(n_new) > 0.0);
        }
        mesh.validate().unwrap();
    }
}
