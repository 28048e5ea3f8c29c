//! Nearest-neighbour queries between two point sets (a kiddo k-d tree, queries in parallel).

use glam::DVec3;
use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use rayon::prelude::*;

/// Queries per rayon task: coarse enough that two cores are not swamped by scheduling.
const QUERY_CHUNK: usize = 8192;

/// Bucket size of the k-d tree leaves.
const BUCKET: usize = 32;

/// The nearest point of a set to one query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// Index of the nearest point in the searched set.
    pub index: u32,
    /// Euclidean distance to it.
    pub distance: f64,
}

/// For every query point, its nearest point among `points` (ties broken by the tree).
///
/// Returns one entry per query, in query order; empty when `points` is empty. The result does not
/// depend on the thread count: each query is answered independently and results are gathered in
/// order. Coordinates must be finite.
pub fn nearest_neighbours(points: &[DVec3], queries: &[DVec3]) -> Vec<Nearest> {
    if points.is_empty() {
        return Vec::new();
    }
    let coords: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
    let tree: ImmutableKdTree<f64, u32, 3, BUCKET> = ImmutableKdTree::new_from_slice(&coords);
    let answer = |q: &DVec3| {
        let nn = tree.nearest_one::<SquaredEuclidean>(&q.to_array());
        Nearest {
            index: nn.item,
            distance: nn.distance.sqrt(),
        }
    };
    if queries.len() <= QUERY_CHUNK {
        return queries.iter().map(answer).collect();
    }
    queries
        .par_chunks(QUERY_CHUNK)
        .map(|chunk| chunk.iter().map(answer).collect::<Vec<_>>())
        .collect::<Vec<_>>()
        .concat()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn point() -> impl Strategy<Value = DVec3> {
        // Coarse grid so that duplicates and ties occur.
        (-8i32..8, -8i32..8, -8i32..8)
            .prop_map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64) * 0.25)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn matches_brute_force(
            points in prop::collection::vec(point(), 1..200),
            queries in prop::collection::vec(point(), 0..60),
        ) {
            let got = nearest_neighbours(&points, &queries);
            prop_assert_eq!(got.len(), queries.len());
            for (q, nn) in queries.iter().zip(&got) {
                let best = points.iter().map(|p| p.distance(*q)).fold(f64::INFINITY, f64::min);
                prop_assert!((nn.distance - best).abs() < 1e-12);
                prop_assert!((points[nn.index as usize].distance(*q) - best).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn large_query_sets_are_answered_in_order() {
        let points: Vec<DVec3> = (0..1000).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        let queries: Vec<DVec3> = (0..20000)
            .map(|i| DVec3::new((i % 1000) as f64 + 0.1, 0.0, 0.0))
            .collect();
        let got = nearest_neighbours(&points, &queries);
        for (i, nn) in got.iter().enumerate() {
            assert_eq!(nn.index as usize, i % 1000);
            assert!((nn.distance - 0.1).abs() < 1e-9);
        }
        assert!(nearest_neighbours(&[], &queries).is_empty());
    }
}
