//! The last step of an SDF input's finish: the mesh fitted to the field's zero set, every vertex
//! moved along its normal as far as it can go without folding or crossing a face.

use std::collections::HashMap;

use glam::DVec3;
use roar_mesh::Mesh;
use roar_mesh::spatial::{Sdf, area_weighted_vertex_normals, triangle_normal};

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
    /// Vertices that kept their place or moved part of the way: a move too long for their
    /// faces, a face it would turn over, or an intersection it would make.
    pub held: usize,
}

/// Fits `mesh` to the zero set of `sdf`: `options.steps` times, every vertex moves along its
/// normal by minus the mean first-order distance `f/|∇f|` over its faces (area-weighted, each
/// face's mean taken at its edge midpoints, the quadrature exact for a distance quadratic over
/// the face). Then each vertex's move is shortened to `max_move_fraction` of its smallest height,
/// moves that would make faces intersect are shortened or cancelled (`limit_steps`) and moves
/// that turn a face over (its normal against the old one) are undone. The topology stays. An
/// undone move can, rarely, meet a shortened one, so a caller that needs the mesh free of
/// self-intersections checks the result (the finish keeps it only if it is clean).
///
/// Why: the loop's mesh sits on the surface only as far as the render, planar and SDF losses
/// pull it, and the fill splits that bring it to a large budget put their new vertices on the
/// old edges' chords. On a field the surface is known everywhere. Each face is fitted, not each
/// vertex: vertices on the zero set would put the faces of a curved part inside it (the chords
/// of a sphere), which at 5,000 faces costs more than it gains.
pub fn fit_to_zero_set(mesh: &mut Mesh, sdf: &dyn Sdf, options: &ZeroSetOptions) -> ZeroSetStats {
    // Compact, the mesh's vertex ids are the indices of `to_triangles`.
    mesh.compact();
    let (positions, triangles) = mesh.to_triangles();
    let edges = FaceEdges::new(&triangles);
    let mut fitted = positions.clone();
    for _ in 0..options.steps {
        let offsets = mean_distances(&fitted, &triangles, &edges, sdf, options.epsilon);
        let normals = area_weighted_vertex_normals(&fitted, &triangles);
        for ((p, n), d) in fitted.iter_mut().zip(&normals).zip(&offsets) {
            *p -= *n * *d;
        }
    }

    let heights = smallest_heights(&positions, &triangles);
    let mut moved = fitted.clone();
    for ((target, &old), &height) in moved.iter_mut().zip(&positions).zip(&heights) {
        let length = (*target - old).length();
        let longest = options.max_move_fraction * height;
        if !length.is_finite() {
            *target = old;
        } else if length > longest {
            *target = old + (*target - old) * (longest / length);
        }
    }
    limit_steps(
        &positions,
        &mut moved,
        &triangles,
        &LimiterOptions::default(),
    );
    undo_turned_faces(&positions, &mut moved, &triangles);

    let fitted = moved.iter().zip(&fitted).filter(|(a, b)| a == b).count();
    mesh.positions_mut().copy_from_slice(&moved);
    ZeroSetStats {
        fitted,
        held: positions.len() - fitted,
    }
}

/// The edges of a triangle list, each once, and each face's three edges.
struct FaceEdges {
    /// Vertex pairs, lower index first.
    edges: Vec<[u32; 2]>,
    /// Per face, the indices into `edges` of its three edges.
    faces: Vec<[usize; 3]>,
}

impl FaceEdges {
    fn new(triangles: &[[u32; 3]]) -> Self {
        let mut index = HashMap::with_capacity(triangles.len() * 3 / 2);
        let mut edges = Vec::with_capacity(triangles.len() * 3 / 2);
        let faces = triangles
            .iter()
            .map(|t| {
                [0, 1, 2].map(|k| {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let key = [a.min(b), a.max(b)];
                    *index.entry(key).or_insert_with(|| {
                        edges.push(key);
                        edges.len() - 1
                    })
                })
            })
            .collect();
        Self { edges, faces }
    }
}

/// Per vertex, the area-weighted mean over its faces of the first-order distance `f/|∇f|`
/// averaged at each face's edge midpoints (0 for a vertex in no face).
fn mean_distances(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    edges: &FaceEdges,
    sdf: &dyn Sdf,
    epsilon: f64,
) -> Vec<f64> {
    let midpoints: Vec<DVec3> = edges
        .edges
        .iter()
        .map(|&[a, b]| 0.5 * (positions[a as usize] + positions[b as usize]))
        .collect();
    let mut values = vec![0.0; midpoints.len()];
    let mut gradients = vec![DVec3::ZERO; midpoints.len()];
    sdf.values_and_gradients(&midpoints, &mut values, &mut gradients);
    let distances: Vec<f64> = values
        .iter()
        .zip(&gradients)
        .map(|(&f, g)| f / (g.length() + epsilon))
        .collect();
    let mut sums = vec![(0.0, 0.0); positions.len()];
    for (t, face_edges) in triangles.iter().zip(&edges.faces) {
        let p = t.map(|i| positions[i as usize]);
        let area = (p[1] - p[0]).cross(p[2] - p[0]).length();
        let distance = face_edges.iter().map(|&e| distances[e]).sum::<f64>() / 3.0;
        for &v in t {
            let (weighted, weight) = &mut sums[v as usize];
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

/// Puts back the corners of every face whose normal turned by more than 90° until none does
/// (each round puts back at least one vertex, so it ends). The positions it leaves were not
/// among those the step limiter checked, so they are not certain to be free of intersections.
fn undo_turned_faces(before: &[DVec3], moved: &mut [DVec3], triangles: &[[u32; 3]]) {
    loop {
        let mut undone = 0;
        for t in triangles {
            let [a, b, c] = t.map(|i| i as usize);
            let old = triangle_normal(before[a], before[b], before[c]);
            let new = triangle_normal(moved[a], moved[b], moved[c]);
            if old.dot(new) <= 0.0 {
                for i in [a, b, c] {
                    if moved[i] != before[i] {
                        moved[i] = before[i];
                        undone += 1;
                    }
                }
            }
        }
        if undone == 0 {
            return;
        }
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
        assert_eq!(stats.held, 0);
        assert_eq!(stats.fitted, mesh.n_vertices());
        let (positions, triangles) = mesh.to_triangles();
        for p in &positions {
            assert!(p.length() > 1.0 && p.length() < 1.005, "{}", p.length());
        }
        let edges = FaceEdges::new(&triangles);
        let left = mean_distances(&positions, &triangles, &edges, &sphere, 1e-10);
        for d in left {
            assert!(d.abs() < 1e-4, "{d}");
        }
        mesh.validate().unwrap();
    }

    #[test]
    fn a_move_long_against_the_faces_is_shortened() {
        // Radius 0.5 against a unit-sphere field: every move (0.5) is longer than half of the
        // smallest heights of a level-2 icosphere's faces, so each goes only that far.
        let mut mesh = icosphere(2);
        for p in mesh.positions_mut() {
            *p *= 0.5;
        }
        let (before, triangles) = mesh.to_triangles();
        let heights = smallest_heights(&before, &triangles);
        let sphere = FnSdf::new(|p: DVec3| p.length() - 1.0);
        let stats = fit_to_zero_set(&mut mesh, &sphere, &ZeroSetOptions::default());
        assert_eq!(stats.fitted, 0);
        assert_eq!(stats.held, mesh.n_vertices());
        for ((p, old), height) in mesh.positions().iter().zip(&before).zip(&heights) {
            assert!(p.length() > old.length());
            let moved = (*p - *old).length();
            assert!((moved - 0.5 * height).abs() < 1e-9, "{moved} {height}");
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
        assert!(stats.held > 0, "{stats:?}");
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
