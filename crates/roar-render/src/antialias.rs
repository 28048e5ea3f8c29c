//! Analytic antialiasing in the manner of Laine et al. 2020 (nvdiffrast), written from the
//! paper's description.
//!
//! For every pair of horizontally or vertically adjacent pixels that see different triangles (or
//! a triangle and the background), the triangle in front (smaller depth, or the only one) is
//! asked where the segment between the two pixel centres leaves it. If the edge it leaves through
//! is a *silhouette* edge in this view (no single neighbour across it, or the neighbour folds
//! back so both opposite vertices lie on the same side of the edge in screen space) and is
//! steep enough for the pair's direction (|dy| ≥ |dx| for horizontal pairs, |dx| > |dy| for
//! vertical ones, so each edge is handled by one direction), the crossing parameter
//! `t ∈ [0, 1]` (0 at the front pixel's centre, 1 at the other's) places the edge inside one of
//! the two pixels' boxes. That pixel gets the true box-filtered coverage:
//! * `t < ½`: the front pixel loses `α = ½ − t` of its area to the other colour,
//!   `I_front += α (c_other − c_front)`;
//! * `t ≥ ½`: the front triangle reaches `α = t − ½` into the other pixel,
//!   `I_other += α (c_front − c_other)`.
//!
//! The blend is continuous in `t` (zero at `t = ½`), and `t` is a closed-form function of the
//! edge endpoints' pixel coordinates, so coverage gets position gradients through it.

use crate::camera::ProjectedVertex;
use crate::raster::BACKGROUND;
use crate::topology::{EdgeNeighbors, NO_NEIGHBOR};

/// Most triangles a pair's segment is followed through to find the silhouette edge.
const MAX_WALK: usize = 4;

/// One antialiasing blend, recorded for the backward pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AaItem {
    /// Pixel whose colour changes (`I_target += alpha · (c_source − c_target)`).
    pub target: u32,
    /// Pixel whose (un-antialiased) colour is blended in.
    pub source: u32,
    /// Whether the target is the pixel covered by the front triangle (`t < ½`).
    pub front_is_target: bool,
    /// The front triangle.
    pub face: u32,
    /// Vertex indices `(a, b)` of the silhouette edge, in the face's winding.
    pub edge: [u32; 2],
    /// Crossing parameter along the segment from the front pixel's centre to the other's.
    pub t: f64,
    /// Blend weight in `[0, ½]`.
    pub alpha: f64,
    /// `dα/dt`: −1 or +1, or 0 when `t` was clamped to `[0, 1]`.
    pub dalpha_dt: f64,
}

impl AaItem {
    /// `(front pixel, other pixel)` of the pair.
    pub fn pixels(&self) -> (u32, u32) {
        if self.front_is_target {
            (self.target, self.source)
        } else {
            (self.source, self.target)
        }
    }
}

/// Edge function `cross(b − a, p − a)`.
fn edge_fn(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

/// Parameter `t` where the line through `a, b` crosses the segment `p → q`
/// (`t = E(p) / (E(p) − E(q))`), or `None` when the segment is parallel to the line.
pub fn crossing(a: [f64; 2], b: [f64; 2], p: [f64; 2], q: [f64; 2]) -> Option<f64> {
    let (ep, eq) = (edge_fn(a, b, p), edge_fn(a, b, q));
    let d = ep - eq;
    if d == 0.0 { None } else { Some(ep / d) }
}

/// Gradient of [`crossing`] with respect to `(a.x, a.y, b.x, b.y)`.
pub fn crossing_grad(a: [f64; 2], b: [f64; 2], p: [f64; 2], q: [f64; 2]) -> [f64; 4] {
    let (ep, eq) = (edge_fn(a, b, p), edge_fn(a, b, q));
    let d = ep - eq;
    if d == 0.0 {
        return [0.0; 4];
    }
    // ∂E(s)/∂(ax, ay, bx, by) = (b.y − s.y, s.x − b.x, s.y − a.y, a.x − s.x).
    let de = |s: [f64; 2]| [b[1] - s[1], s[0] - b[0], s[1] - a[1], a[0] - s[0]];
    let (dp, dq) = (de(p), de(q));
    let inv = 1.0 / (d * d);
    [0, 1, 2, 3].map(|k| (ep * dq[k] - eq * dp[k]) * inv)
}

/// Blend weight of a crossing at `t`: `(alpha, dalpha_dt, front_is_target)`; `t` outside
/// `[0, 1]` is clamped and gets a zero derivative.
pub fn blend_weight(t: f64) -> (f64, f64, bool) {
    let clamped = !(0.0..=1.0).contains(&t);
    let t = t.clamp(0.0, 1.0);
    let (alpha, slope, front) = if t < 0.5 {
        (0.5 - t, -1.0, true)
    } else {
        (t - 0.5, 1.0, false)
    };
    (alpha, if clamped { 0.0 } else { slope }, front)
}

/// Pixel centre of pixel index `p` in an image `width` wide.
pub fn pixel_centre(p: u32, width: u32) -> [f64; 2] {
    [(p % width) as f64 + 0.5, (p / width) as f64 + 0.5]
}

/// Per face, bit k set when edge k is a silhouette edge in this view: no unique neighbour
/// across it, or the neighbour folds back (both opposite vertices on the same side of the
/// edge in screen space).
pub fn silhouette_masks(
    verts: &[ProjectedVertex],
    triangles: &[[u32; 3]],
    neighbors: &EdgeNeighbors,
) -> Vec<u8> {
    silhouettes_and_orientations(verts, triangles, neighbors).0
}

/// [`silhouette_masks`], and per face and edge `k` the edge function of edge `k` at the third
/// corner (`edge_fn(c_k, c_{k+1}, c_{k+2})`, the face's signed doubled area in screen space,
/// computed per edge), which the pair walk reads instead of computing it again per step.
fn silhouettes_and_orientations(
    verts: &[ProjectedVertex],
    triangles: &[[u32; 3]],
    neighbors: &EdgeNeighbors,
) -> (Vec<u8>, Vec<[f64; 3]>) {
    let xy = |v: u32| {
        let v = &verts[v as usize];
        [v.x, v.y]
    };
    let mut masks = Vec::with_capacity(triangles.len());
    let mut orientations = Vec::with_capacity(triangles.len());
    for (tri, opposite) in triangles.iter().zip(&neighbors.opposite) {
        // Each corner is read once for the three edges.
        let corner = tri.map(xy);
        let mut mask = 0u8;
        let mut own = [0.0; 3];
        for k in 0..3 {
            let a = corner[k];
            let b = corner[(k + 1) % 3];
            own[k] = edge_fn(a, b, corner[(k + 2) % 3]);
            let silhouette = opposite[k] == NO_NEIGHBOR || {
                let other = edge_fn(a, b, xy(opposite[k]));
                own[k] * other >= 0.0
            };
            if silhouette {
                mask |= 1 << k;
            }
        }
        masks.push(mask);
        orientations.push(own);
    }
    (masks, orientations)
}

/// Per face, whether the walk of [`PairContext::pair`] started on it can meet a silhouette
/// edge: whether a face with one lies fewer than [`MAX_WALK`] steps away across non-silhouette
/// edges (the only ones the walk crosses). The other faces' pairs have no item, so the walk is
/// skipped for them; with small triangles they are most of a view's differing pairs.
fn silhouette_within_walk(masks: &[u8], neighbors: &EdgeNeighbors) -> Vec<bool> {
    let mut reach: Vec<bool> = masks.iter().map(|&mask| mask != 0).collect();
    for _ in 1..MAX_WALK {
        let previous = reach.clone();
        for (f, reached) in reach.iter_mut().enumerate() {
            // A non-silhouette edge always has its one neighbour.
            *reached |=
                (0..3).any(|k| masks[f] & (1 << k) == 0 && previous[neighbors.face[f][k] as usize]);
        }
    }
    reach
}

/// Finds the antialiasing items of one view. Items come in a deterministic order (horizontal
/// pairs row by row, then vertical pairs), then are stably sorted by target pixel.
pub fn antialias_items(
    verts: &[ProjectedVertex],
    triangles: &[[u32; 3]],
    neighbors: &EdgeNeighbors,
    ids: &[u32],
    depth: &[f32],
    width: u32,
    height: u32,
) -> Vec<AaItem> {
    let w = width as usize;
    if w == 0 || ids.len() != w * height as usize {
        return Vec::new();
    }
    let (masks, orientations) = silhouettes_and_orientations(verts, triangles, neighbors);
    let reach = silhouette_within_walk(&masks, neighbors);
    let mut items = Vec::new();
    let ctx = PairContext {
        verts,
        triangles,
        neighbors,
        ids,
        depth,
        masks: &masks,
        orientations: &orientations,
        reach: &reach,
    };
    for (y, row) in ids.chunks_exact(w).enumerate() {
        for_each_differing(row, &row[1..], |x| {
            if ctx.may_have_item(row[x], row[x + 1])
                && let Some(item) = ctx.pair(y * w + x, [x, y], true, w)
            {
                items.push(item);
            }
        });
    }
    let horizontal = items.len();
    for_each_differing(ids, &ids[w.min(ids.len())..], |p| {
        if ctx.may_have_item(ids[p], ids[p + w])
            && let Some(item) = ctx.pair(p, [p % w, p / w], false, w)
        {
            items.push(item);
        }
    });
    sorted_by_target(&items, horizontal)
}

/// The items stably sorted by target pixel, when `items[..horizontal]` come from horizontal
/// pairs and the rest from vertical pairs, each in pixel order.
///
/// A horizontal pair `(p, p + 1)` targets `p` or `p + 1`, so the horizontal targets never
/// decrease; a vertical pair `(p, p + w)` targets `p` (up) or `p + w` (down), so the targets of
/// each kind never decrease either. Merging the three sorted runs, ties taken horizontal first,
/// then down (its pair starts `w` pixels earlier), then up, is the stable sort's order, in one
/// pass instead of a sort.
fn sorted_by_target(items: &[AaItem], horizontal: usize) -> Vec<AaItem> {
    let (across, vertical) = items.split_at(horizontal);
    type Keep = fn(&&AaItem) -> bool;
    let kinds: [(&[AaItem], Keep); 3] = [
        (across, |_| true),
        (vertical, |it| it.target > it.source),
        (vertical, |it| it.target < it.source),
    ];
    let mut runs = kinds.map(|(list, keep)| list.iter().filter(keep).peekable());
    let mut sorted = Vec::with_capacity(items.len());
    loop {
        let mut best: Option<(usize, u32)> = None;
        for (run, iter) in runs.iter_mut().enumerate() {
            if let Some(it) = iter.peek()
                && best.is_none_or(|(_, target)| it.target < target)
            {
                best = Some((run, it.target));
            }
        }
        let Some((run, _)) = best else {
            return sorted;
        };
        sorted.extend(runs[run].next().copied());
    }
}

/// Calls `visit(i)` for every `i < min(a.len(), b.len())` with `a[i] != b[i]`, in increasing
/// order. Runs of equal ids (the background, the inside of a face) are skipped eight at a time.
#[inline]
fn for_each_differing(a: &[u32], b: &[u32], mut visit: impl FnMut(usize)) {
    const BLOCK: usize = 8;
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut start = 0;
    for (ab, bb) in a.chunks_exact(BLOCK).zip(b.chunks_exact(BLOCK)) {
        // One OR of XORs tells whether the whole block is equal (SIMD-friendly).
        let mut any = 0u32;
        for i in 0..BLOCK {
            any |= ab[i] ^ bb[i];
        }
        if any != 0 {
            for i in 0..BLOCK {
                if ab[i] != bb[i] {
                    visit(start + i);
                }
            }
        }
        start += BLOCK;
    }
    for i in start..n {
        if a[i] != b[i] {
            visit(i);
        }
    }
}

struct PairContext<'a> {
    verts: &'a [ProjectedVertex],
    triangles: &'a [[u32; 3]],
    neighbors: &'a EdgeNeighbors,
    ids: &'a [u32],
    depth: &'a [f32],
    masks: &'a [u8],
    /// Per face, [`silhouettes_and_orientations`]' edge functions at the third corners.
    orientations: &'a [[f64; 3]],
    /// Per face, [`silhouette_within_walk`].
    reach: &'a [bool],
}

impl PairContext<'_> {
    fn xy(&self, v: u32) -> [f64; 2] {
        let v = &self.verts[v as usize];
        [v.x, v.y]
    }

    /// Whether face `b` is `a`'s neighbour across an edge that is not a silhouette of `a`
    /// (false when either is the background).
    fn smooth_across(&self, a: u32, b: u32) -> bool {
        if a == BACKGROUND || b == BACKGROUND {
            return false;
        }
        let adjacent = self.neighbors.face[a as usize];
        let mask = self.masks[a as usize];
        (0..3).any(|k| adjacent[k] == b && mask & (1 << k) == 0)
    }

    /// Whether a pair of pixels that see faces `a` and `b` (different) can have an item,
    /// whichever is in front: not when neither face can reach a silhouette edge, nor when they
    /// are joined by a non-silhouette edge (the same smooth surface). Most differing pairs are
    /// one or the other, and this settles them without the depth comparison and the walk.
    fn may_have_item(&self, a: u32, b: u32) -> bool {
        // The face in front is one of the two, never the background.
        let reaches = |f: u32| f != BACKGROUND && self.reach[f as usize];
        (reaches(a) || reaches(b)) && !(self.smooth_across(a, b) && self.smooth_across(b, a))
    }

    /// The item of pixel `p` at `p_xy` and its right (`horizontal`) or lower neighbour in an
    /// image `w` wide, if the pair straddles a silhouette.
    fn pair(&self, p: usize, p_xy: [usize; 2], horizontal: bool, w: usize) -> Option<AaItem> {
        let (q, q_xy) = if horizontal {
            (p + 1, [p_xy[0] + 1, p_xy[1]])
        } else {
            (p + w, [p_xy[0], p_xy[1] + 1])
        };
        let (fp, fq) = (self.ids[p], self.ids[q]);
        let p_in_front = if fp == BACKGROUND {
            false
        } else if fq == BACKGROUND {
            true
        } else {
            let (dp, dq) = (self.depth[p], self.depth[q]);
            dp < dq || (dp == dq && self.triangles[fp as usize] < self.triangles[fq as usize])
        };
        let ((front, front_xy), (other, other_xy)) = if p_in_front {
            ((p, p_xy), (q, q_xy))
        } else {
            ((q, q_xy), (p, p_xy))
        };
        let face = self.ids[front];
        if !self.reach[face as usize] {
            return None;
        }
        let mask = self.masks[face as usize];
        // Exit for the interior case: the other pixel sees the neighbour across a
        // non-silhouette edge, i.e. the same smooth surface.
        if self.smooth_across(face, self.ids[other]) {
            return None;
        }
        // `pixel_centre` of the two pixels, from their coordinates (the same values).
        let centre = |[x, y]: [usize; 2]| [x as f64 + 0.5, y as f64 + 0.5];
        let (cf, co) = (centre(front_xy), centre(other_xy));
        // Follow the segment front → other through the front surface: leave the front triangle
        // through the first edge its edge function falls below zero on; if that edge is not a
        // silhouette, continue in the neighbour across it (a fan around a vertex), up to a few
        // steps, until a silhouette edge is crossed before the other pixel's centre.
        let mut face = face;
        let mut mask = mask;
        let mut found = None;
        for _ in 0..MAX_WALK {
            let tri = self.triangles[face as usize];
            let corner = tri.map(|v| self.xy(v));
            let orientation = self.orientations[face as usize];
            let mut best: Option<(usize, f64)> = None;
            for k in 0..3 {
                let a = corner[k];
                let b = corner[(k + 1) % 3];
                let orient = orientation[k];
                let (ef, eo) = (edge_fn(a, b, cf) * orient, edge_fn(a, b, co) * orient);
                if ef > eo {
                    let t = ef / (ef - eo);
                    if best.is_none_or(|(_, bt)| t < bt) {
                        best = Some((k, t));
                    }
                }
            }
            let (k, t) = best?;
            if t > 1.0 {
                return None;
            }
            if mask & (1 << k) != 0 {
                found = Some((face, tri, k, t));
                break;
            }
            face = self.neighbors.face[face as usize][k];
            mask = self.masks[face as usize];
        }
        let (face, tri, k, t) = found?;
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        let (pa, pb) = (self.xy(a), self.xy(b));
        let (dx, dy) = ((pb[0] - pa[0]).abs(), (pb[1] - pa[1]).abs());
        let steep_enough = if horizontal { dy >= dx } else { dx > dy };
        if !steep_enough {
            return None;
        }
        let (alpha, dalpha_dt, front_is_target) = blend_weight(t);
        let (target, source) = if front_is_target {
            (front, other)
        } else {
            (other, front)
        };
        Some(AaItem {
            target: target as u32,
            source: source as u32,
            front_is_target,
            face,
            edge: [a, b],
            t,
            alpha,
            dalpha_dt,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientations_are_the_edge_functions_at_the_third_corners() {
        // Random screen vertices, a strip of triangles sharing edges (so some edges have a
        // neighbour and some fold back), plus a lone triangle and a degenerate one.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 512.0
        };
        let verts: Vec<ProjectedVertex> = (0..40)
            .map(|_| ProjectedVertex {
                x: next(),
                y: next(),
                z: 0.5,
                cx: 0.0,
                cy: 0.0,
                w: 1.0,
            })
            .collect();
        let mut triangles: Vec<[u32; 3]> = (0..30).map(|i| [i, i + 1, i + 2]).collect();
        triangles.push([35, 36, 37]);
        triangles.push([38, 38, 39]);
        let neighbors = EdgeNeighbors::new(&triangles);
        let (masks, orientations) = silhouettes_and_orientations(&verts, &triangles, &neighbors);
        assert_eq!(masks, silhouette_masks(&verts, &triangles, &neighbors));
        let xy = |v: u32| [verts[v as usize].x, verts[v as usize].y];
        for (tri, orientation) in triangles.iter().zip(&orientations) {
            for k in 0..3 {
                let expected = edge_fn(xy(tri[k]), xy(tri[(k + 1) % 3]), xy(tri[(k + 2) % 3]));
                assert_eq!(
                    orientation[k].to_bits(),
                    expected.to_bits(),
                    "{tri:?} edge {k}"
                );
            }
        }
    }

    #[test]
    fn skipping_faces_out_of_walking_reach_keeps_every_item() {
        use crate::camera::star_cameras;
        use crate::raster::rasterize;
        use roar_mesh::shapes::{icosphere, perturbed, torus};
        // Bumpy closed surfaces with triangles of a few pixels (most differing pairs lie inside
        // the surface, far from a silhouette) and self-occlusion, seen from several cameras:
        // the items equal those of walking every pair that is not across a smooth edge.
        let (mut items, mut skipped_faces) = (0, 0);
        let shapes = [
            perturbed(&icosphere(4), 0.02, 3),
            perturbed(&torus(48, 24, 0.6, 0.25), 0.01, 4),
        ];
        for shape in &shapes {
            let (positions, triangles) = shape.to_triangles();
            let neighbors = EdgeNeighbors::new(&triangles);
            for cam in star_cameras(3, 2, 160, 128) {
                let verts: Vec<ProjectedVertex> =
                    positions.iter().map(|&p| cam.project(p * 0.9)).collect();
                let raster = rasterize(&verts, &triangles, 160, 128, false);
                let (ids, depth) = (&raster.ids, &raster.depth);
                let fast = antialias_items(&verts, &triangles, &neighbors, ids, depth, 160, 128);
                let (masks, orientations) =
                    silhouettes_and_orientations(&verts, &triangles, &neighbors);
                let reach = vec![true; triangles.len()];
                let every_face = PairContext {
                    verts: &verts,
                    triangles: &triangles,
                    neighbors: &neighbors,
                    ids,
                    depth,
                    masks: &masks,
                    orientations: &orientations,
                    reach: &reach,
                };
                let mut walked = Vec::new();
                let w = 160;
                for p in 0..ids.len() {
                    if p % w + 1 < w && ids[p] != ids[p + 1] {
                        walked.extend(every_face.pair(p, [p % w, p / w], true, w));
                    }
                }
                let horizontal = walked.len();
                for p in 0..ids.len() - w {
                    if ids[p] != ids[p + w] {
                        walked.extend(every_face.pair(p, [p % w, p / w], false, w));
                    }
                }
                assert_eq!(fast, sorted_by_target(&walked, horizontal));
                items += fast.len();
                skipped_faces += silhouette_within_walk(&masks, &neighbors)
                    .iter()
                    .filter(|&&reached| !reached)
                    .count();
            }
        }
        assert!(items > 1000, "only {items} items");
        assert!(skipped_faces > 1000, "only {skipped_faces} faces skipped");
    }

    #[test]
    fn merged_items_are_the_stable_sort_by_target() {
        // Items of random pairs in scan order (horizontal row by row, then vertical), each
        // targeting either pixel; `face` records the scan position to tell ties apart.
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let mut next = |n: u32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 33) as u32 % n
        };
        for case in 0..200 {
            let (w, h) = (1 + next(9), 1 + next(9));
            let mut items = Vec::new();
            let item = |p: u32, q: u32, items: &mut Vec<AaItem>, pick: u32| {
                let (target, source) = if pick == 0 { (p, q) } else { (q, p) };
                items.push(AaItem {
                    target,
                    source,
                    front_is_target: pick == 0,
                    face: items.len() as u32,
                    edge: [0, 1],
                    t: 0.25,
                    alpha: 0.25,
                    dalpha_dt: -1.0,
                });
            };
            for p in 0..w * h {
                if p % w + 1 < w && next(3) == 0 {
                    item(p, p + 1, &mut items, next(2));
                }
            }
            let horizontal = items.len();
            for p in 0..w * h.saturating_sub(1) {
                if next(3) == 0 {
                    item(p, p + w, &mut items, next(2));
                }
            }
            let mut expected = items.clone();
            expected.sort_by_key(|it| it.target);
            assert_eq!(
                sorted_by_target(&items, horizontal),
                expected,
                "case {case}"
            );
        }
    }

    #[test]
    fn differing_positions_match_a_plain_scan() {
        // Runs of equal ids with changes at scattered places, lengths around the block size.
        for n in [0usize, 1, 7, 8, 9, 17, 64, 101] {
            let a: Vec<u32> = (0..n as u32).map(|i| (i / 5) % 3).collect();
            let b: Vec<u32> = (0..n as u32 + 2).map(|i| (i / 7) % 3).collect();
            let mut found = Vec::new();
            for_each_differing(&a, &b, |i| found.push(i));
            let plain: Vec<usize> = (0..n).filter(|&i| a[i] != b[i]).collect();
            assert_eq!(found, plain, "n {n}");
        }
    }

    #[test]
    fn crossing_finite_difference() {
        let cases = [
            ([3.2, 1.1], [3.9, 5.0], [3.5, 2.5], [4.5, 2.5]),
            ([0.3, 7.0], [1.1, -2.0], [0.5, 0.5], [1.5, 0.5]),
            ([2.0, 2.3], [6.0, 2.9], [4.5, 2.5], [4.5, 3.5]),
        ];
        let h = 1e-6;
        for (a, b, p, q) in cases {
            let g = crossing_grad(a, b, p, q);
            for k in 0..4 {
                let bump = |s: f64| {
                    let (mut a2, mut b2) = (a, b);
                    if k < 2 {
                        a2[k] += s;
                    } else {
                        b2[k - 2] += s;
                    }
                    crossing(a2, b2, p, q).unwrap()
                };
                let fd = (bump(h) - bump(-h)) / (2.0 * h);
                assert!(
                    (fd - g[k]).abs() < 1e-6 * fd.abs() + 1e-9,
                    "{k}: {fd} vs {}",
                    g[k]
                );
            }
        }
    }

    #[test]
    fn crossing_matches_line_intersection() {
        // Vertical line x = 4.2 between centres 3.5 and 4.5: t = 0.7.
        let t = crossing([4.2, 0.0], [4.2, 9.0], [3.5, 2.5], [4.5, 2.5]).unwrap();
        assert!((t - 0.7).abs() < 1e-12);
        assert_eq!(
            crossing([0.0, 0.0], [1.0, 0.0], [0.5, 0.5], [1.5, 0.5]),
            None
        );
    }

    #[test]
    fn blend_weight_finite_difference() {
        let h = 1e-7;
        for t in [0.05, 0.3, 0.49, 0.51, 0.8, 0.97] {
            let (alpha, slope, _) = blend_weight(t);
            let fd = (blend_weight(t + h).0 - blend_weight(t - h).0) / (2.0 * h);
            assert!((fd - slope).abs() < 1e-6, "t {t}: {fd} vs {slope}");
            assert!((alpha - (t - 0.5).abs()).abs() < 1e-15);
        }
        assert_eq!(blend_weight(-0.2), (0.5, 0.0, true));
        assert_eq!(blend_weight(1.3), (0.5, 0.0, false));
        // Continuous at ½: both branches give zero.
        assert!(blend_weight(0.5 - 1e-12).0 < 1e-11 && blend_weight(0.5).0 == 0.0);
    }
}
