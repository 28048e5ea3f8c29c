//! Incremental self-intersection detection across the rounds of [`super::untangle`].

use glam::DVec3;
use roar_mesh::spatial::faces_intersect_filtered as faces_cross;
use roar_mesh::spatial::{Aabb, TriangleBvh, intersecting_pairs};

/// Keeps the intersecting pairs of the previous round and re-tests only faces with a moved
/// corner: a pair of two unmoved faces is exactly as it was. The first call (and the first
/// after [`PairFinder::invalidate`], e.g. after a topology change) runs the full
/// [`intersecting_pairs`].
#[derive(Default)]
pub(super) struct PairFinder {
    state: Option<Previous>,
}

/// What the previous call saw: its tree (refitted), positions and pairs.
type Previous = (TriangleBvh, Vec<DVec3>, Vec<(u32, u32)>);

impl PairFinder {
    /// Forgets everything; the next [`PairFinder::find`] starts from scratch.
    pub fn invalidate(&mut self) {
        self.state = None;
    }

    /// Every intersecting pair `(i, j)`, `i < j`, sorted, exactly as [`intersecting_pairs`]
    /// reports it. `triangles` must be those of the previous call unless invalidated.
    pub fn find(&mut self, positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
        let Some((bvh, last, pairs)) = &mut self.state else {
            let pairs = intersecting_pairs(positions, triangles);
            let bvh = TriangleBvh::build(positions, triangles);
            self.state = Some((bvh, positions.to_vec(), pairs.clone()));
            return pairs;
        };
        let moved: Vec<bool> = positions
            .iter()
            .zip(last.iter())
            .map(|(a, b)| a != b)
            .collect();
        let changed: Vec<bool> = triangles
            .iter()
            .map(|t| t.iter().any(|&i| moved[i as usize]))
            .collect();
        bvh.refit(positions);
        let mut out: Vec<(u32, u32)> = pairs
            .iter()
            .copied()
            .filter(|&(i, j)| !changed[i as usize] && !changed[j as usize])
            .collect();
        let mut candidates = Vec::new();
        for (f, &tf) in triangles.iter().enumerate() {
            if !changed[f] {
                continue;
            }
            let b = Aabb::from_triangle(tf.map(|i| positions[i as usize]));
            candidates.clear();
            bvh.faces_in_aabb(&b, |g| candidates.push(g as usize));
            for &g in &candidates {
                if g == f || (changed[g] && g < f) {
                    continue;
                }
                if faces_cross(positions, tf, triangles[g]) {
                    out.push((f.min(g) as u32, f.max(g) as u32));
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        last.copy_from_slice(positions);
        pairs.clone_from(&out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;

    #[test]
    fn incremental_pairs_match_a_full_recount() {
        let (mut p, t) = icosphere(3).to_triangles();
        let mut finder = PairFinder::default();
        assert!(finder.find(&p, &t).is_empty());
        // Push the north cap through the south pole, then part of it back.
        for x in p.iter_mut().filter(|x| x.z > 0.8) {
            x.z = -1.3;
        }
        assert_eq!(finder.find(&p, &t), intersecting_pairs(&p, &t));
        assert!(!intersecting_pairs(&p, &t).is_empty());
        for x in p.iter_mut().filter(|x| x.x > 0.0 && x.z < -1.0) {
            x.z = 0.9;
        }
        assert_eq!(finder.find(&p, &t), intersecting_pairs(&p, &t));
    }
}
