//! The soup turned to face outward piece by piece, for the winding number of module
//! `winding_solid`.
//!
//! The generalized winding number counts a triangle with the sign of its orientation, so one
//! piece of a closed surface stored inside out (common in soups: a part exported mirrored, a
//! patch of a CAD model with flipped normals) pulls the winding number inside the object down
//! by twice that piece's solid angle, and a punctured surface with a few such pieces no longer
//! reads as enclosing anything. Following Takayama et al. 2014 ("Simple and robust mesh
//! orientation"): the soup is cut into *patches* (faces joined across edges shared by exactly
//! two faces, made consistent with each other), and each patch is turned to face the side from
//! which it is seen more: from points spread over the patch, rays in a fixed set of directions
//! either escape the soup's bounds or hit another triangle, and each side's escapes, weighted
//! by the cosine to the patch's normal (ambient occlusion), are summed. A patch no ray escapes
//! from, or one seen equally from both sides (an open sheet), keeps its orientation.
//!
//! ```text
//!        escapes ↑ ↗ ↖            the outer side of a piece of a punctured tube sees the
//!     ───────────────────         open sky; its inner side sees the sky only through holes,
//!        blocked ↓ ↘ ↙            so the outer side wins and the normal is turned to it
//! ```

use glam::DVec3;
use rayon::prelude::*;
use roar_mesh::spatial::TriangleBvh;
use std::collections::HashMap;

/// Ray directions per sample point (spread evenly over the sphere).
const DIRECTIONS: usize = 32;

/// Sample points over all patches together, shared out by area.
const TOTAL_SAMPLES: usize = 4096;

/// Most sample points one patch gets.
const MAX_SAMPLES_PER_PATCH: usize = 16;

/// Patches tested, largest first; the rest (tiny pieces of a shattered soup, whose solid angles
/// barely move the winding number) keep their orientation.
const MAX_TESTED_PATCHES: usize = 16_384;

/// What [`orient_patches`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Orientation {
    /// Patches of the soup (faces joined across two-face edges).
    pub patches: usize,
    /// Patches turned over because their back was seen more than their front.
    pub flipped: usize,
}

/// `soup` without its second twins (module doc of `winding_solid`), each patch turned to face
/// the side it is seen from (module doc). Promises: the same triangles as the deduplicated
/// soup, in the same order, each either as it was or reversed.
pub(crate) fn orient_patches(soup: &[[DVec3; 3]]) -> (Vec<[DVec3; 3]>, Orientation) {
    let mut soup = first_of_each_twin_pair(soup);
    let (patch, reversed, patches) = consistent_patches(&soup);
    for (t, &r) in soup.iter_mut().zip(&reversed) {
        if r {
            t.swap(1, 2);
        }
    }
    let turn = patches_seen_from_behind(&soup, &patch, patches);
    let flipped = turn.iter().filter(|&&turned| turned).count();
    for (t, &p) in soup.iter_mut().zip(&patch) {
        if turn[p as usize] {
            t.swap(1, 2);
        }
    }
    (soup, Orientation { patches, flipped })
}

/// `soup` without the second of each pair of twins (the same corners in the other orientation).
///
/// A triangle and its twin cancel in the winding number, and the pipeline's target T′ keeps both
/// twins of every pair its pixel-count rule leaves undecided, which on a punctured closed
/// surface is most faces (their inner side is seen through the holes): with both, `w` is 0
/// everywhere.
fn first_of_each_twin_pair(soup: &[[DVec3; 3]]) -> Vec<[DVec3; 3]> {
    let mut seen = std::collections::HashSet::with_capacity(soup.len());
    soup.iter()
        .filter(|t| {
            let mut corners = t.map(corner_key);
            corners.sort_unstable();
            seen.insert(corners)
        })
        .copied()
        .collect()
}

/// Bit pattern of a corner, with −0.0 read as 0.0, so equal corners weld.
fn corner_key(p: DVec3) -> [u64; 3] {
    p.to_array().map(|x| (x + 0.0).to_bits())
}

/// For each face, its patch and whether it must be reversed to agree with the patch's first
/// face; and the number of patches. Faces are joined across edges shared by exactly two faces
/// (after welding equal corners); a non-orientable patch (a Möbius strip) keeps the orientation
/// its breadth-first walk gives it.
fn consistent_patches(soup: &[[DVec3; 3]]) -> (Vec<u32>, Vec<bool>, usize) {
    let mut ids: HashMap<[u64; 3], u32> = HashMap::with_capacity(soup.len());
    let corners: Vec<[u32; 3]> = soup
        .iter()
        .map(|t| {
            t.map(|p| {
                let next = ids.len() as u32;
                *ids.entry(corner_key(p)).or_insert(next)
            })
        })
        .collect();
    // (low vertex, high vertex, face, whether the face runs low → high).
    let mut edges: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(3 * soup.len());
    for (f, c) in corners.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), f as u32, a < b));
        }
    }
    edges.sort_unstable();
    // Up to three neighbours per face, each with whether the two run the shared edge the same
    // way (then one of them must be reversed to agree).
    let mut neighbours: Vec<Vec<(u32, bool)>> = vec![Vec::new(); soup.len()];
    for group in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if let [(_, _, f, df), (_, _, g, dg)] = group
            && f != g
        {
            neighbours[*f as usize].push((*g, df == dg));
            neighbours[*g as usize].push((*f, df == dg));
        }
    }
    let mut patch = vec![u32::MAX; soup.len()];
    let mut reversed = vec![false; soup.len()];
    let mut patches = 0u32;
    let mut queue = Vec::new();
    for start in 0..soup.len() {
        if patch[start] != u32::MAX {
            continue;
        }
        patch[start] = patches;
        queue.push(start as u32);
        while let Some(f) = queue.pop() {
            for &(g, same_way) in &neighbours[f as usize] {
                if patch[g as usize] == u32::MAX {
                    patch[g as usize] = patches;
                    reversed[g as usize] = reversed[f as usize] ^ same_way;
                    queue.push(g);
                }
            }
        }
        patches += 1;
    }
    (patch, reversed, patches as usize)
}

/// For each patch of the consistently oriented `soup`, whether its back is seen more than its
/// front (module doc). Samples: [`TOTAL_SAMPLES`] shared out by area, at least one and at most
/// [`MAX_SAMPLES_PER_PATCH`] per patch, for the [`MAX_TESTED_PATCHES`] largest patches; each
/// sample sits at the centroid of the face where the patch's running area crosses its share.
fn patches_seen_from_behind(soup: &[[DVec3; 3]], patch: &[u32], patches: usize) -> Vec<bool> {
    let area = |t: &[DVec3; 3]| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
    let mut patch_area = vec![0.0; patches];
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); patches];
    for (f, t) in soup.iter().enumerate() {
        patch_area[patch[f] as usize] += area(t);
        members[patch[f] as usize].push(f as u32);
    }
    let total: f64 = patch_area.iter().sum();
    let mut order: Vec<usize> = (0..patches).collect();
    order.sort_by(|&a, &b| patch_area[b].total_cmp(&patch_area[a]).then(a.cmp(&b)));
    order.truncate(MAX_TESTED_PATCHES);
    // (patch, face) of every sample.
    let mut samples: Vec<(usize, u32)> = Vec::new();
    for &p in &order {
        let share = (TOTAL_SAMPLES as f64 * patch_area[p] / total).round() as usize;
        let n = share.clamp(1, MAX_SAMPLES_PER_PATCH);
        let step = patch_area[p] / n as f64;
        let mut next = 0.5 * step;
        let mut running = 0.0;
        for &f in &members[p] {
            running += area(&soup[f as usize]);
            while running >= next {
                samples.push((p, f));
                next += step;
            }
        }
    }
    let positions: Vec<DVec3> = soup.iter().flatten().copied().collect();
    let triangles: Vec<[u32; 3]> = (0..soup.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    let bvh = TriangleBvh::build(&positions, &triangles);
    let Some(bounds) = bvh.aabb() else {
        return vec![false; patches];
    };
    let reach = 2.0 * bounds.diagonal();
    let offset = 1e-9 * bounds.diagonal();
    let directions = sphere_directions(DIRECTIONS);
    // (front score, back score) of each sample: cosine-weighted escapes on each side.
    let scores: Vec<(f64, f64)> = samples
        .par_iter()
        .map(|&(_, f)| {
            let t = soup[f as usize];
            let normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            let centroid = (t[0] + t[1] + t[2]) / 3.0;
            let (mut front, mut back) = (0.0, 0.0);
            for &d in &directions {
                let cosine = d.dot(normal);
                if cosine == 0.0 {
                    continue;
                }
                let origin = centroid + offset * cosine.signum() * normal;
                if bvh.ray_cast(origin, d, reach).is_none() {
                    if cosine > 0.0 {
                        front += cosine;
                    } else {
                        back -= cosine;
                    }
                }
            }
            (front, back)
        })
        .collect();
    let mut sums = vec![(0.0, 0.0); patches];
    for (&(p, _), &(front, back)) in samples.iter().zip(&scores) {
        sums[p].0 += front;
        sums[p].1 += back;
    }
    sums.iter().map(|&(front, back)| back > front).collect()
}

/// `n` unit vectors spread evenly over the sphere (the Fibonacci lattice).
fn sphere_directions(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f64 / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::spatial::exact_winding_number;

    /// The closed unit cube as outward triangles, each square split along its diagonal.
    fn cube() -> Vec<[DVec3; 3]> {
        let mesh = roar_mesh::shapes::cube();
        mesh.faces()
            .map(|f| mesh.face_vertices(f).map(|v| mesh.position(v)))
            .collect()
    }

    fn winding(soup: &[[DVec3; 3]], q: DVec3) -> f64 {
        let positions: Vec<DVec3> = soup.iter().flatten().copied().collect();
        let triangles: Vec<[u32; 3]> = (0..soup.len() as u32)
            .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
            .collect();
        exact_winding_number(&positions, &triangles, q)
    }

    fn centre(soup: &[[DVec3; 3]]) -> DVec3 {
        soup.iter().flatten().sum::<DVec3>() / (3 * soup.len()) as f64
    }

    #[test]
    fn pieces_stored_inside_out_are_turned_to_face_outward() {
        // The cube's six sides as separate pieces (each shrunk a little towards its own centre,
        // so no corners are shared), every other side reversed: the winding number inside
        // drops from about 1 to about 0.
        let sides: Vec<[[DVec3; 3]; 2]> = cube()
            .chunks(2)
            .map(|pair| {
                let mid = centre(pair);
                let shrink = |t: [DVec3; 3]| t.map(|p| mid + 0.95 * (p - mid));
                [shrink(pair[0]), shrink(pair[1])]
            })
            .collect();
        let outward: Vec<[DVec3; 3]> = sides.iter().flatten().copied().collect();
        let inside = centre(&outward);
        assert!(winding(&outward, inside) > 0.9);
        let mut soup = Vec::new();
        for (i, side) in sides.iter().enumerate() {
            for t in side {
                soup.push(if i % 2 == 0 { [t[0], t[2], t[1]] } else { *t });
            }
        }
        assert!(winding(&soup, inside).abs() < 0.1);
        let (oriented, orientation) = orient_patches(&soup);
        assert_eq!((orientation.patches, orientation.flipped), (6, 3));
        assert_eq!(oriented, outward);
    }

    #[test]
    fn a_patch_agrees_with_its_neighbours_before_it_is_judged() {
        // One face of the closed cube reversed: its patch is the whole cube, made consistent
        // with its first face, then seen from outside.
        let mut soup = cube();
        soup[3].swap(1, 2);
        let (oriented, orientation) = orient_patches(&soup);
        assert_eq!(orientation.patches, 1);
        assert_eq!(oriented, cube());
    }

    #[test]
    fn a_flat_sheet_and_a_hidden_piece_keep_their_orientation() {
        let sheet = vec![
            [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0)],
            [DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
        ];
        let reversed: Vec<[DVec3; 3]> = sheet.iter().map(|t| [t[0], t[2], t[1]]).collect();
        assert_eq!(orient_patches(&sheet).0, sheet);
        assert_eq!(orient_patches(&reversed).0, reversed);
        // A small triangle inside the closed cube, facing either way: no ray escapes from it.
        for flip in [false, true] {
            let mut soup = cube();
            let c = centre(&soup);
            let mut hidden = [c, c + 0.1 * DVec3::X, c + 0.1 * DVec3::Y];
            if flip {
                hidden.swap(1, 2);
            }
            soup.push(hidden);
            let (oriented, orientation) = orient_patches(&soup);
            assert_eq!(orientation.flipped, 0);
            assert_eq!(oriented.last(), Some(&hidden));
        }
    }

    #[test]
    fn twins_are_counted_once() {
        let mut soup = cube();
        let twins: Vec<[DVec3; 3]> = soup.iter().map(|t| [t[0], t[2], t[1]]).collect();
        soup.extend(twins);
        let (oriented, _) = orient_patches(&soup);
        assert_eq!(oriented, cube());
    }
}
