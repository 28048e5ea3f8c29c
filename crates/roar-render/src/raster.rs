//! Watertight z-buffered rasterization of one view.
//!
//! Vertices are snapped to 1/256 pixel and edge functions are evaluated exactly in `i64` at pixel
//! centres, stepped incrementally over each triangle's clamped bounding box. A pixel centre lying
//! exactly on an edge belongs to the triangle for which the tie rule (equivalent to moving the
//! sample point by an infinitesimal in a fixed direction, i.e. a top-left rule) says so, hence two
//! triangles sharing an edge never both cover, nor both miss, a pixel. Depth is the NDC `z/w`,
//! affine in screen space, evaluated in `f32`; ties break on the triangle's vertex indices, so the
//! result does not depend on the order of the triangle list.

use crate::camera::ProjectedVertex;

/// Triangle id stored in pixels that no triangle covers.
pub const BACKGROUND: u32 = u32::MAX;

/// Sub-pixel resolution of the fixed-point vertex snap (bits).
const SUBPIXEL_BITS: u32 = 8;
const ONE: i64 = 1 << SUBPIXEL_BITS;
const HALF: i64 = ONE / 2;

/// The id and depth buffers of one view, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterBuffers {
    /// Visible triangle per pixel, [`BACKGROUND`] where empty.
    pub ids: Vec<u32>,
    /// NDC depth `z/w` of the visible triangle, `+∞` where empty.
    pub depth: Vec<f32>,
}

/// Whether a triangle with this pixel-space signed area (`cross(p1 − p0, p2 − p0)`, y down)
/// faces the camera (counter-clockwise seen from the camera).
pub fn is_front_facing(signed_area: f64) -> bool {
    signed_area < 0.0
}

fn snap(v: f64) -> i64 {
    (v * ONE as f64).round() as i64
}

fn floor_div(a: i64, b: i64) -> i64 {
    a.div_euclid(b)
}

fn ceil_div(a: i64, b: i64) -> i64 {
    -((-a).div_euclid(b))
}

/// `(⌊a / d⌋, a mod d)` for `d > 0`, with one hardware division.
fn div_mod_floor(a: i64, d: i64) -> (i64, i64) {
    let (q, r) = (a / d, a % d);
    if r < 0 { (q - 1, r + d) } else { (q, r) }
}

/// Triangles whose clamped bounding box has at most this many pixels are filled by testing the
/// edge functions at every pixel, cheaper there than setting up the span stepping (six
/// divisions and the edge sort per triangle). Measured with `loss_profile` on a run's 10k-face
/// working mesh (36 views at 512²): rasterization took 543, 492, 473, 484 and 500 M
/// instructions per evaluation at 16, 32, 64, 128 and 256.
const SMALL_BOX: i64 = 64;

/// How one edge function `e(i) = e + step · i` (`i` the pixel offset in a row) limits a row.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Bound {
    /// `step > 0`: offsets `i ≥ −q` pass.
    Left,
    /// `step < 0`: offsets `i ≤ q` pass.
    Right,
    /// `step = 0`: the whole row passes iff `q ≥ 0` (`q` is then the edge function itself).
    Flat,
}

#[derive(Clone, Copy)]
/// Exact row-to-row tracking of where one edge function crosses zero: `q, r` with
/// `e = q·d + r, 0 ≤ r < d` (`d = |step|`, or 1 for a flat edge), advanced by the per-row
/// increment `row_step = qt·d + rt` with additions only (two divisions per edge and triangle
/// instead of one per row, and no per-pixel edge tests).
struct EdgeStepper {
    bound: Bound,
    q: i64,
    r: i64,
    d: i64,
    qt: i64,
    rt: i64,
}

impl EdgeStepper {
    fn new(e: i64, step: i64, row_step: i64) -> Self {
        let bound = match step.signum() {
            1 => Bound::Left,
            -1 => Bound::Right,
            _ => Bound::Flat,
        };
        let d = step.abs().max(1);
        let (q, r) = div_mod_floor(e, d);
        let (qt, rt) = div_mod_floor(row_step, d);
        Self {
            bound,
            q,
            r,
            d,
            qt,
            rt,
        }
    }

    /// Moves to the next row (`e += row_step`), without a data-dependent branch.
    fn advance(&mut self) {
        self.q += self.qt;
        self.r += self.rt;
        let carry = (self.r >= self.d) as i64;
        self.r -= carry * self.d;
        self.q += carry;
    }
}

/// Side of the square pixel tiles whose largest depth [`DepthTiles`] keeps.
const TILE: usize = 8;

/// The largest depth of every `TILE`×`TILE` block of a depth buffer (`+∞` where a block shows
/// any background), taken once the triangles facing the camera are drawn. Later writes only
/// lower depths, so the maxima stay upper bounds of the buffer.
struct DepthTiles {
    /// Tiles per row.
    columns: usize,
    max: Vec<f32>,
}

impl DepthTiles {
    fn new(depth: &[f32], w: usize, h: usize) -> Self {
        // Depths are never NaN (a NaN depth never passes the depth test), so the larger of two
        // is a plain comparison, which vectorizes.
        let larger = |m: f32, d: f32| if d > m { d } else { m };
        let columns = w.div_ceil(TILE);
        let mut max = Vec::with_capacity(columns * h.div_ceil(TILE));
        // Per band of `TILE` rows: the column maxima, then the maxima of `TILE` columns.
        let mut column_max = vec![f32::NEG_INFINITY; w];
        for band in depth.chunks(TILE * w) {
            column_max.fill(f32::NEG_INFINITY);
            for row in band.chunks_exact(w) {
                for (m, &d) in column_max.iter_mut().zip(row) {
                    *m = larger(*m, d);
                }
            }
            max.extend(
                column_max
                    .chunks(TILE)
                    .map(|block| block.iter().fold(f32::NEG_INFINITY, |m, &d| larger(m, d))),
            );
        }
        Self { columns, max }
    }

    /// Whether every pixel of the box `x0..=x1, y0..=y1` (inside the image) holds a depth
    /// below `z`.
    fn all_below(&self, x0: i64, x1: i64, y0: i64, y1: i64, z: f32) -> bool {
        let (tx0, tx1) = (x0 as usize / TILE, x1 as usize / TILE);
        (y0 as usize / TILE..y1 as usize / TILE + 1).all(|ty| {
            self.max[ty * self.columns + tx0..ty * self.columns + tx1 + 1]
                .iter()
                .all(|&m| m < z)
        })
    }
}

/// The buffers being drawn and what every triangle reads.
struct Canvas<'a> {
    verts: &'a [ProjectedVertex],
    triangles: &'a [[u32; 3]],
    /// Vertices snapped once, so shared edges get identical fixed-point endpoints.
    snapped: Vec<[i64; 2]>,
    /// Image width and height in pixels.
    w: usize,
    h: usize,
    ids: Vec<u32>,
    depth: Vec<f32>,
}

/// Rasterizes `triangles` over `verts` (already projected, all in front of the near plane).
///
/// The triangles facing the camera are drawn first, in order, then the others, in order, each
/// skipped when [`DepthTiles`] shows its every pixel already nearer than its nearest possible
/// depth. The result does not depend on the drawing order (see the module doc: the depth test
/// keeps the least `(depth, vertex indices)`; equal triangles face the same way, so they keep
/// their relative order and the first still wins), and a skipped triangle would fail the depth
/// test at every pixel, so this gives the buffers of drawing all triangles in order. On a closed
/// surface most back faces lie behind front faces, and skipping them saves about a third of the
/// fill work.
pub fn rasterize(
    verts: &[ProjectedVertex],
    triangles: &[[u32; 3]],
    width: u32,
    height: u32,
    cull_backfaces: bool,
) -> RasterBuffers {
    rasterize_counting(verts, triangles, width, height, cull_backfaces).0
}

/// [`rasterize`], and how many triangles it skipped as hidden.
fn rasterize_counting(
    verts: &[ProjectedVertex],
    triangles: &[[u32; 3]],
    width: u32,
    height: u32,
    cull_backfaces: bool,
) -> (RasterBuffers, usize) {
    let (w, h) = (width as usize, height as usize);
    let mut canvas = Canvas {
        verts,
        triangles,
        snapped: verts.iter().map(|v| [snap(v.x), snap(v.y)]).collect(),
        w,
        h,
        ids: vec![BACKGROUND; w * h],
        depth: vec![f32::INFINITY; w * h],
    };
    let mut back = Vec::new();
    for f in 0..triangles.len() {
        let [q0, q1, q2] = canvas.corners(f);
        let area = (q1[0] - q0[0]) * (q2[1] - q0[1]) - (q1[1] - q0[1]) * (q2[0] - q0[0]);
        if area < 0 {
            // Orient so that inside means all three edge functions are positive.
            canvas.draw(f, [q0, q2, q1], None);
        } else if area > 0 && !cull_backfaces {
            back.push(f);
        }
    }
    let mut skipped = 0;
    if !back.is_empty() {
        let tiles = DepthTiles::new(&canvas.depth, w, h);
        for f in back {
            let corners = canvas.corners(f);
            skipped += usize::from(!canvas.draw(f, corners, Some(&tiles)));
        }
    }
    let Canvas { ids, depth, .. } = canvas;
    (RasterBuffers { ids, depth }, skipped)
}

impl Canvas<'_> {
    /// The snapped corners of triangle `f`.
    fn corners(&self, f: usize) -> [[i64; 2]; 3] {
        self.triangles[f].map(|i| self.snapped[i as usize])
    }

    /// Draws triangle `f` whose `corners` (snapped, in the order that makes the inside positive)
    /// span a non-zero area, unless `tiles` show it hidden. Returns false when it was skipped
    /// as hidden.
    fn draw(&mut self, f: usize, corners: [[i64; 2]; 3], tiles: Option<&DepthTiles>) -> bool {
        let (w, h, triangles) = (self.w, self.h, self.triangles);
        let Some([x0, x1, y0, y1]) = pixel_box(corners, w, h) else {
            return true;
        };
        let (zx32, zy32, zo32) = depth_plane(self.verts, triangles[f], x0, y0);
        if let Some(tiles) = tiles
            && let Some(z) = least_depth(zo32, zx32, zy32, x1 - x0, y1 - y0)
            && tiles.all_below(x0, x1, y0, y1, z)
        {
            return false;
        }
        let (mut row, step_x, step_y) = edge_functions(corners, x0, y0);
        let fid = f as u32;
        let (depth, ids) = (&mut self.depth, &mut self.ids);
        let visit = |depth: &mut [f32], ids: &mut [u32], p: usize, z: f32| {
            let cur = depth[p];
            if z < cur
                || (z == cur
                    && ids[p] != BACKGROUND
                    && triangles[fid as usize] < triangles[ids[p] as usize])
            {
                depth[p] = z;
                ids[p] = fid;
            }
        };
        // The row and pixel loops use half-open ranges: an inclusive range carries an extra
        // "exhausted" flag through every step of these hot loops.
        if (x1 - x0 + 1) * (y1 - y0 + 1) <= SMALL_BOX {
            for y in y0..y1 + 1 {
                let mut e = row;
                let z_row = zo32 + zy32 * (y - y0) as f32;
                for x in x0..x1 + 1 {
                    if (e[0] | e[1] | e[2]) >= 0 {
                        let z = z_row + zx32 * (x - x0) as f32;
                        visit(depth, ids, y as usize * w + x as usize, z);
                    }
                    for k in 0..3 {
                        e[k] += step_x[k];
                    }
                }
                for k in 0..3 {
                    row[k] += step_y[k];
                }
            }
            return true;
        }
        // Left bounds first, then right, then flat, so each row runs branch-free loops of
        // per-triangle constant length.
        let unsorted = [0, 1, 2].map(|k| EdgeStepper::new(row[k], step_x[k], step_y[k]));
        let mut edges = unsorted;
        let mut n = 0;
        for bound in [Bound::Left, Bound::Right, Bound::Flat] {
            for edge in unsorted.iter().filter(|e| e.bound == bound) {
                edges[n] = *edge;
                n += 1;
            }
        }
        let num_left = edges.iter().filter(|e| e.bound == Bound::Left).count();
        let num_right = edges.iter().filter(|e| e.bound == Bound::Right).count();
        let (left, rest) = edges.split_at_mut(num_left);
        let (right, flat) = rest.split_at_mut(num_right);
        for y in y0..y1 + 1 {
            // The covered pixels of a row form one span (the triangle is convex): intersect the
            // half-lines where each edge function is non-negative, exactly, then only depth-test
            // inside the span.
            let mut lo = 0;
            let mut hi = x1 - x0;
            for edge in left.iter_mut() {
                lo = lo.max(-edge.q);
                edge.advance();
            }
            for edge in right.iter_mut() {
                hi = hi.min(edge.q);
                edge.advance();
            }
            for edge in flat.iter_mut() {
                if edge.q < 0 {
                    hi = lo - 1;
                }
                edge.advance();
            }
            let z_row = zo32 + zy32 * (y - y0) as f32;
            if lo > hi {
                continue;
            }
            let span = y as usize * w + (x0 + lo) as usize..y as usize * w + (x0 + hi) as usize + 1;
            let pixels = depth[span.clone()].iter_mut().zip(&mut ids[span]);
            for ((cur, id), i) in pixels.zip(lo..) {
                let z = z_row + zx32 * i as f32;
                if z < *cur
                    || (z == *cur
                        && *id != BACKGROUND
                        && triangles[fid as usize] < triangles[*id as usize])
                {
                    *cur = z;
                    *id = fid;
                }
            }
        }
        true
    }
}

/// The pixels whose centres the box of `corners` (snapped) covers, `[x0, x1, y0, y1]` inclusive
/// and clipped to a `w`×`h` image; `None` when it holds no pixel centre.
fn pixel_box(corners: [[i64; 2]; 3], w: usize, h: usize) -> Option<[i64; 4]> {
    let min_x = corners.iter().map(|c| c[0]).min().unwrap_or(0);
    let max_x = corners.iter().map(|c| c[0]).max().unwrap_or(0);
    let min_y = corners.iter().map(|c| c[1]).min().unwrap_or(0);
    let max_y = corners.iter().map(|c| c[1]).max().unwrap_or(0);
    let x0 = ceil_div(min_x - HALF, ONE).max(0);
    let x1 = floor_div(max_x - HALF, ONE).min(w as i64 - 1);
    let y0 = ceil_div(min_y - HALF, ONE).max(0);
    let y1 = floor_div(max_y - HALF, ONE).min(h as i64 - 1);
    (x0 <= x1 && y0 <= y1).then_some([x0, x1, y0, y1])
}

/// The edge functions E(p) = cross(b − a, p − a) of `corners` (in the order that makes the
/// inside positive), biased by the tie rule, at the centre of pixel `(x0, y0)`, and their steps
/// per pixel along x and y: `(row, step_x, step_y)`.
fn edge_functions(corners: [[i64; 2]; 3], x0: i64, y0: i64) -> ([i64; 3], [i64; 3], [i64; 3]) {
    let px0 = x0 * ONE + HALF;
    let py0 = y0 * ONE + HALF;
    let mut row = [0i64; 3];
    let mut step_x = [0i64; 3];
    let mut step_y = [0i64; 3];
    for k in 0..3 {
        let a = corners[k];
        let b = corners[(k + 1) % 3];
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let include_ties = dy > 0 || (dy == 0 && dx < 0);
        let bias = if include_ties { 0 } else { -1 };
        row[k] = dx * (py0 - a[1]) - dy * (px0 - a[0]) + bias;
        step_x[k] = -dy * ONE;
        step_y[k] = dx * ONE;
    }
    (row, step_x, step_y)
}

/// The depth plane of triangle `tri`, z = z0 + zx (x − x0) + zy (y − y0) in float pixel
/// coordinates, as `(zx, zy, z0)` in f32 with z0 at the centre of pixel `(x0, y0)` (flat for a
/// triangle of zero projected area).
fn depth_plane(verts: &[ProjectedVertex], tri: [u32; 3], x0: i64, y0: i64) -> (f32, f32, f32) {
    let [v0, v1, v2] = tri.map(|i| &verts[i as usize]);
    let (d1x, d1y, d1z) = (v1.x - v0.x, v1.y - v0.y, v1.z - v0.z);
    let (d2x, d2y, d2z) = (v2.x - v0.x, v2.y - v0.y, v2.z - v0.z);
    let det = d1x * d2y - d1y * d2x;
    let (zx, zy) = if det != 0.0 {
        ((d1z * d2y - d2z * d1y) / det, (d2z * d1x - d1z * d2x) / det)
    } else {
        (0.0, 0.0)
    };
    let z_origin = v0.z + zx * (x0 as f64 + 0.5 - v0.x) + zy * (y0 as f64 + 0.5 - v0.y);
    (zx as f32, zy as f32, z_origin as f32)
}

/// A lower bound of the depths the fill loops compute over a box of `0..=width` × `0..=height`
/// pixel offsets, `(zo + zy·dy) + zx·dx` in f32 (`None` when it may not be finite). Each
/// rounded operation is monotone in its operands, so the depth is monotone in `dx` and in
/// `dy`, and its least value lies at a corner of the box: the least row start plus the least
/// row offset.
fn least_depth(zo: f32, zx: f32, zy: f32, width: i64, height: i64) -> Option<f32> {
    let rows = [zo + zy * 0 as f32, zo + zy * height as f32];
    let offsets = [zx * 0 as f32, zx * width as f32];
    let row = if rows[1] < rows[0] { rows[1] } else { rows[0] };
    let offset = if offsets[1] < offsets[0] {
        offsets[1]
    } else {
        offsets[0]
    };
    let least = row + offset;
    let finite = rows.iter().chain(&offsets).all(|v| v.is_finite()) && least.is_finite();
    finite.then_some(least)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The straightforward rasterizer: edge functions tested at every pixel of the bounding box.
    fn rasterize_per_pixel(
        verts: &[ProjectedVertex],
        triangles: &[[u32; 3]],
        width: u32,
        height: u32,
        cull_backfaces: bool,
    ) -> RasterBuffers {
        let (w, h) = (width as usize, height as usize);
        let mut ids = vec![BACKGROUND; w * h];
        let mut depth = vec![f32::INFINITY; w * h];
        // Snap once per vertex so shared edges get identical fixed-point endpoints.
        let snapped: Vec<[i64; 2]> = verts.iter().map(|v| [snap(v.x), snap(v.y)]).collect();
        for (f, tri) in triangles.iter().enumerate() {
            let [i0, i1, i2] = tri.map(|i| i as usize);
            let (q0, q1, q2) = (snapped[i0], snapped[i1], snapped[i2]);
            let area = (q1[0] - q0[0]) * (q2[1] - q0[1]) - (q1[1] - q0[1]) * (q2[0] - q0[0]);
            if area == 0 || (cull_backfaces && area > 0) {
                continue;
            }
            // Orient so that inside means all three edge functions are positive.
            let corners = if area > 0 { [q0, q1, q2] } else { [q0, q2, q1] };
            let Some([x0, x1, y0, y1]) = pixel_box(corners, w, h) else {
                continue;
            };
            let (mut row, step_x, step_y) = edge_functions(corners, x0, y0);
            let (zx32, zy32, zo32) = depth_plane(verts, *tri, x0, y0);
            let fid = f as u32;
            for y in y0..=y1 {
                let mut e = row;
                let z_row = zo32 + zy32 * (y - y0) as f32;
                let base = y as usize * w;
                for x in x0..=x1 {
                    if (e[0] | e[1] | e[2]) >= 0 {
                        let z = z_row + zx32 * (x - x0) as f32;
                        let p = base + x as usize;
                        let cur = depth[p];
                        if z < cur
                            || (z == cur
                                && ids[p] != BACKGROUND
                                && triangles[fid as usize] < triangles[ids[p] as usize])
                        {
                            depth[p] = z;
                            ids[p] = fid;
                        }
                    }
                    e[0] += step_x[0];
                    e[1] += step_x[1];
                    e[2] += step_x[2];
                }
                row[0] += step_y[0];
                row[1] += step_y[1];
                row[2] += step_y[2];
            }
        }
        RasterBuffers { ids, depth }
    }

    #[test]
    fn skipping_hidden_back_faces_gives_the_buffers_of_drawing_all() {
        use crate::camera::star_cameras;
        use roar_mesh::shapes::{icosphere, perturbed, torus};
        // Closed surfaces (most back faces hidden), with some faces repeated and some reversed
        // copies (depth ties between a front and a back face), seen from several cameras.
        let mut skipped = 0;
        let shapes = [
            perturbed(&icosphere(3), 0.05, 1),
            perturbed(&torus(24, 12, 0.6, 0.25), 0.03, 2),
        ];
        for (s, shape) in shapes.iter().enumerate() {
            let (positions, mut tris) = shape.to_triangles();
            for f in (0..tris.len()).step_by(7) {
                let t = tris[f];
                tris.push(if f % 2 == 0 { t } else { [t[0], t[2], t[1]] });
            }
            for cam in star_cameras(3, 2, 96, 80) {
                let verts: Vec<ProjectedVertex> =
                    positions.iter().map(|&p| cam.project(p * 0.9)).collect();
                for cull in [false, true] {
                    let (fast, n) = rasterize_counting(&verts, &tris, 96, 80, cull);
                    let slow = rasterize_per_pixel(&verts, &tris, 96, 80, cull);
                    assert_eq!(fast, slow, "shape {s}, cull {cull}");
                    skipped += n;
                }
            }
        }
        assert!(skipped > 1000, "only {skipped} triangles skipped");
    }

    /// Tiny deterministic generator (xorshift) for the brute-force comparison.
    fn next(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn span_rasterizer_matches_per_pixel_edge_tests() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let (w, h) = (37u32, 29u32);
        for case in 0..200 {
            let n = 3 + case % 7;
            let verts: Vec<ProjectedVertex> = (0..n)
                .map(|i| {
                    // Some vertices on pixel centres or edges, some off-screen, some random.
                    // Every other case small triangles (the per-pixel path), else large ones.
                    let scale = if case % 2 == 0 { 1.0 } else { 0.12 };
                    let (mut x, mut y) = (
                        (next(&mut state) * 50.0 - 6.0) * scale + 15.0 * (1.0 - scale),
                        (next(&mut state) * 40.0 - 5.0) * scale + 12.0 * (1.0 - scale),
                    );
                    if i % 3 == 0 {
                        x = x.floor() + 0.5;
                        y = y.floor() + if case % 4 < 2 { 0.5 } else { 0.0 };
                    }
                    ProjectedVertex {
                        x,
                        y,
                        z: next(&mut state),
                        cx: 0.0,
                        cy: 0.0,
                        w: 1.0,
                    }
                })
                .collect();
            let tris: Vec<[u32; 3]> = (0..2 * n)
                .map(|_| [0, 1, 2].map(|_| (next(&mut state) * n as f64) as u32 % n))
                .collect();
            for cull in [false, true] {
                let fast = rasterize(&verts, &tris, w, h, cull);
                let slow = rasterize_per_pixel(&verts, &tris, w, h, cull);
                assert_eq!(fast, slow, "case {case}, cull {cull}");
            }
        }
        // Long thin slivers: steep and shallow edges over a wide image.
        let sliver = [
            ProjectedVertex {
                x: 0.3,
                y: 0.2,
                z: 0.1,
                cx: 0.0,
                cy: 0.0,
                w: 1.0,
            },
            ProjectedVertex {
                x: 500.7,
                y: 3.1,
                z: 0.5,
                cx: 0.0,
                cy: 0.0,
                w: 1.0,
            },
            ProjectedVertex {
                x: 250.5,
                y: 300.5,
                z: 0.9,
                cx: 0.0,
                cy: 0.0,
                w: 1.0,
            },
            ProjectedVertex {
                x: 1.2,
                y: 511.0,
                z: 0.3,
                cx: 0.0,
                cy: 0.0,
                w: 1.0,
            },
        ];
        let tris = [[0, 1, 2], [0, 2, 3], [1, 3, 2], [0, 1, 3]];
        assert_eq!(
            rasterize(&sliver, &tris, 512, 512, false),
            rasterize_per_pixel(&sliver, &tris, 512, 512, false)
        );
    }
}
