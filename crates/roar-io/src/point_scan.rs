//! Unorganised scans: points without a grid, triangulated as the scanner saw them.
//!
//! The points are projected onto the plane facing the scanner (the scan frame's xy plane; the
//! scanner looks along [`SCANNER_VIEW`]), Delaunay-triangulated there (`spade`), and filtered as
//! a range grid's patch is ([`PatchOptions`]): a triangle with an edge longer than
//! `max_edge_factor` × the local spacing (the largest, over its corners, of the corner's
//! shortest Delaunay edge: the sampling distance there, which long edges along the hull or
//! across a gap do not inflate; at most twice the scan's median of those, so sparse outliers
//! far from the surface do not join up) bridges a depth jump or a gap and is dropped, and so is a triangle
//! seen at a grazing angle; the rest face the scanner.

use glam::DVec3;
use spade::{DelaunayTriangulation, Point2, Triangulation};

use crate::range_grid::{PatchOptions, PatchStats, SCANNER_VIEW, keep_facing_scanner};
use crate::soup::TriangleSoup;

/// The patch of the unorganised scan `positions` (scan frame): all points kept as vertices, the
/// filtered Delaunay triangles oriented toward the scanner. Points at the same projected
/// position as an earlier one, and points `spade` cannot take (beyond its coordinate range),
/// stay unreferenced.
pub fn point_scan_patch(positions: &[DVec3], options: &PatchOptions) -> (TriangleSoup, PatchStats) {
    let mut delaunay: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::new();
    // Triangulation vertex → input point.
    let mut input_of = Vec::new();
    for (i, p) in positions.iter().enumerate() {
        if let Ok(handle) = delaunay.insert(Point2::new(p.x, p.y))
            && handle.index() == input_of.len()
        {
            input_of.push(i as u32);
        }
    }
    // Shortest 3-D Delaunay edge at each vertex.
    let mut nearest = vec![f64::INFINITY; input_of.len()];
    for edge in delaunay.undirected_edges() {
        let [a, b] = edge.vertices().map(|v| v.fix().index());
        let length = positions[input_of[a] as usize].distance(positions[input_of[b] as usize]);
        nearest[a] = nearest[a].min(length);
        nearest[b] = nearest[b].min(length);
    }
    let mut sorted: Vec<f64> = nearest.iter().copied().filter(|d| d.is_finite()).collect();
    let middle = sorted.len() / 2;
    let cap = match sorted.is_empty() {
        true => f64::INFINITY,
        false => 2.0 * *sorted.select_nth_unstable_by(middle, f64::total_cmp).1,
    };
    let mut stats = PatchStats::default();
    let mut triangles = Vec::new();
    let toward_scanner = -SCANNER_VIEW;
    for face in delaunay.inner_faces() {
        let corners = face.vertices().map(|v| v.fix().index());
        let local = corners
            .iter()
            .map(|&c| nearest[c])
            .fold(0.0, f64::max)
            .min(cap);
        let t = corners.map(|c| input_of[c]);
        stats.candidates += 1;
        if let Some(t) =
            keep_facing_scanner(positions, t, local, toward_scanner, options, &mut stats)
        {
            triangles.push(t);
        }
    }
    (TriangleSoup::new(positions.to_vec(), triangles), stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `n × n` grid of points of the height field `z(x, y)`, in a scrambled order.
    fn scattered(n: usize, z: impl Fn(f64, f64) -> f64) -> Vec<DVec3> {
        let mut points: Vec<DVec3> = (0..n * n)
            .map(|k| {
                let (x, y) = ((k % n) as f64, (k / n) as f64);
                DVec3::new(x + 0.01 * ((k * 7) % 5) as f64, y, z(x, y))
            })
            .collect();
        points.reverse();
        points
    }

    #[test]
    fn a_flat_cloud_becomes_a_patch_facing_the_scanner() {
        let points = scattered(6, |_, _| 2.0);
        let (patch, stats) = point_scan_patch(&points, &PatchOptions::default());
        assert_eq!(
            stats.candidates,
            patch.triangles.len() + stats.dropped_long_edge
        );
        // The 5 × 5 square is covered once (the jitter of x is at most 0.04).
        let area: f64 = patch
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| patch.positions[i as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum();
        assert!((area - 25.0).abs() < 0.2, "{area}");
        for t in &patch.triangles {
            let [a, b, c] = t.map(|i| patch.positions[i as usize]);
            assert!((b - a).cross(c - a).dot(-SCANNER_VIEW) > 0.0);
        }
    }

    #[test]
    fn a_depth_jump_is_not_bridged() {
        let points = scattered(8, |x, _| if x < 3.5 { 0.0 } else { 10.0 });
        let (patch, stats) = point_scan_patch(&points, &PatchOptions::default());
        assert!(stats.dropped_long_edge >= 2 * 7, "{stats:?}");
        for t in &patch.triangles {
            let z = t.map(|i| patch.positions[i as usize].z);
            assert!(z.iter().all(|&v| v == z[0]), "a triangle spans the step");
        }
    }
}
