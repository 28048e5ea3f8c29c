//! The input soup of [`watertight_init`](super::watertight_init): its valid triangles, their
//! bounds, and the same surface cut into short-edged pieces for the trees.

use super::error::InitError;
use super::voxelize;
use glam::DVec3;

/// Most triangles [`split_long_edges`] produces; past it, long edges are left as they are.
const MAX_SPLIT_TRIANGLES: usize = 4_000_000;

/// The same surface as `soup`, with every triangle cut at the midpoint of its longest edge until no
/// edge is longer than `max_edge`. Closest points are unchanged, but a BVH over the pieces has
/// small boxes, so a query opens few faces even when the soup has huge triangles (a few big
/// triangles overlapping every box made queries test almost every face), and the same holds for
/// the fast winding number's tree (`winding_solid`).
pub(crate) fn split_long_edges(soup: &[[DVec3; 3]], max_edge: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut out: Vec<[DVec3; 3]> = Vec::with_capacity(soup.len());
    let mut stack: Vec<[DVec3; 3]> = Vec::new();
    let limit2 = max_edge * max_edge;
    for t in soup {
        stack.push(*t);
        while let Some(t) = stack.pop() {
            let lengths = [0, 1, 2].map(|k| t[k].distance_squared(t[(k + 1) % 3]));
            let k = (0..3)
                .max_by(|&a, &b| lengths[a].total_cmp(&lengths[b]))
                .unwrap_or(0);
            if lengths[k] <= limit2 || out.len() + stack.len() >= MAX_SPLIT_TRIANGLES {
                out.push(t);
                continue;
            }
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let m = 0.5 * (a + b);
            stack.push([a, m, c]);
            stack.push([m, b, c]);
        }
    }
    let positions: Vec<DVec3> = out.iter().flatten().copied().collect();
    let triangles = (0..out.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    (positions, triangles)
}

/// Bounding box of the soup's corners.
pub(super) fn soup_bounds(soup: &[[DVec3; 3]]) -> (DVec3, DVec3) {
    let (mut min, mut max) = (soup[0][0], soup[0][0]);
    for t in soup {
        for p in t {
            min = min.min(*p);
            max = max.max(*p);
        }
    }
    (min, max)
}

/// Checks indices and coordinates; returns the non-degenerate triangles (never empty).
pub(super) fn valid_triangles(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Result<Vec<[DVec3; 3]>, InitError> {
    if triangles.is_empty() {
        return Err(InitError::EmptyInput);
    }
    let mut soup = Vec::with_capacity(triangles.len());
    for (face, t) in triangles.iter().enumerate() {
        let mut p = [DVec3::ZERO; 3];
        for k in 0..3 {
            let index = t[k];
            let q = *positions
                .get(index as usize)
                .ok_or(InitError::IndexOutOfRange {
                    face,
                    index,
                    vertex_count: positions.len(),
                })?;
            if !q.is_finite() {
                return Err(InitError::NonFiniteCoordinate {
                    vertex: index as usize,
                });
            }
            p[k] = q;
        }
        if !voxelize::is_degenerate(p) {
            soup.push(p);
        }
    }
    if soup.is_empty() {
        return Err(InitError::AllDegenerate {
            count: triangles.len(),
        });
    }
    Ok(soup)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitting_long_edges_keeps_the_surface_and_bounds_the_edges() {
        let soup = vec![[
            DVec3::ZERO,
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(0.0, 3.0, 1.0),
        ]];
        let area = |t: [DVec3; 3]| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        let (positions, triangles) = split_long_edges(&soup, 1.0);
        assert!(triangles.len() > 20);
        let mut total = 0.0;
        for t in &triangles {
            let c = t.map(|i| positions[i as usize]);
            for k in 0..3 {
                assert!(c[k].distance(c[(k + 1) % 3]) <= 1.0 + 1e-12);
                // Every piece lies in the plane of the original triangle.
                let n = (soup[0][1] - soup[0][0]).cross(soup[0][2] - soup[0][0]);
                assert!((c[k] - soup[0][0]).dot(n).abs() < 1e-9);
            }
            total += area(c);
        }
        assert!((total - area(soup[0])).abs() < 1e-9 * area(soup[0]));
    }
}
