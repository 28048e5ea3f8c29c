//! The per-view pipeline (project → rasterize → antialias → shade) and its backward pass, run
//! over all views with rayon and reduced in view order.

use glam::{DMat4, DVec3};
use rayon::prelude::*;

use crate::antialias::{AaItem, antialias_items, crossing_grad, pixel_centre};
use crate::camera::{Camera, ProjectedVertex, project_backward, project_with};
use crate::error::RenderError;
use crate::loss::{LossKind, loss_term};
use crate::normals::{face_normal_backward, face_normals};
use crate::options::RenderOptions;
use crate::raster::BACKGROUND;
use crate::raster::rasterize;
use crate::renders::{Image, Renders, ViewRender};
use crate::topology::EdgeNeighbors;

/// Views processed together before their gradients are summed (bounds memory; the sum order is
/// the view order whatever the thread count).
const VIEW_CHUNK: usize = 8;

fn validate(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    cameras: &[Camera],
) -> Result<(), RenderError> {
    if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
        return Err(RenderError::NonFiniteVertex { vertex });
    }
    for (face, t) in triangles.iter().enumerate() {
        if let Some(&vertex) = t.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(RenderError::IndexOutOfRange {
                face,
                vertex,
                num_vertices: positions.len(),
            });
        }
    }
    for (camera, c) in cameras.iter().enumerate() {
        if c.width == 0 || c.height == 0 {
            return Err(RenderError::EmptyResolution {
                camera,
                width: c.width,
                height: c.height,
            });
        }
    }
    Ok(())
}

fn project_view(
    positions: &[DVec3],
    cam: &Camera,
    camera: usize,
) -> Result<Vec<ProjectedVertex>, RenderError> {
    let m = cam.view_proj();
    // Filled in place: collecting the `Result`s would grow the vector a dozen times per view.
    let mut verts = Vec::with_capacity(positions.len());
    for (vertex, &p) in positions.iter().enumerate() {
        let v = project_with(&m, cam.width, cam.height, p);
        if v.w < crate::camera::NEAR || !v.x.is_finite() || !v.y.is_finite() {
            return Err(RenderError::BehindNearPlane { vertex, camera });
        }
        verts.push(v);
    }
    Ok(verts)
}

/// The part of a view's forward pass that backward needs.
struct ViewGeometry {
    verts: Vec<ProjectedVertex>,
    ids: Vec<u32>,
    depth: Vec<f32>,
    items: Vec<AaItem>,
}

fn forward_view(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    neighbors: &EdgeNeighbors,
    cam: &Camera,
    camera: usize,
    opts: &RenderOptions,
) -> Result<ViewGeometry, RenderError> {
    let verts = project_view(positions, cam, camera)?;
    let raster = rasterize(
        &verts,
        triangles,
        cam.width,
        cam.height,
        opts.cull_backfaces,
    );
    let items = if opts.antialias {
        antialias_items(
            &verts,
            triangles,
            neighbors,
            &raster.ids,
            &raster.depth,
            cam.width,
            cam.height,
        )
    } else {
        Vec::new()
    };
    Ok(ViewGeometry {
        verts,
        ids: raster.ids,
        depth: raster.depth,
        items,
    })
}

#[inline]
fn colour(normals: &[DVec3], id: u32) -> [f64; 4] {
    if id == BACKGROUND {
        [0.0; 4]
    } else {
        let n = normals[id as usize];
        [n.x, n.y, n.z, 1.0]
    }
}

/// Visits every pixel in order with its antialiased colour and the AA items targeting it.
fn shade_view(
    ids: &[u32],
    items: &[AaItem],
    normals: &[DVec3],
    mut visit: impl FnMut(usize, [f64; 4], &[AaItem]),
) {
    let mut next = 0;
    for (p, &id) in ids.iter().enumerate() {
        let base = colour(normals, id);
        let start = next;
        let mut img = base;
        while next < items.len() && items[next].target as usize == p {
            let it = &items[next];
            let src = colour(normals, ids[it.source as usize]);
            for c in 0..4 {
                img[c] += it.alpha * (src[c] - base[c]);
            }
            next += 1;
        }
        visit(p, img, &items[start..next]);
    }
}

/// Per-view gradient: summed loss, dL/d(face normal) per face, and position gradients of the
/// silhouette vertices in item order.
struct ViewGrad {
    loss: f64,
    d_normals: Vec<DVec3>,
    d_positions: Vec<(u32, DVec3)>,
}

/// Where a view's backward pass gets `dL/dI` from (which may also accumulate a loss).
trait Seed {
    /// `dL/dI` of pixel `p`, which shows colour `img`.
    fn pixel(&mut self, p: usize, img: [f64; 4]) -> [f64; 4];

    /// Seeds the unblended pixels `start..start + ids.len()`, which show the colours of the
    /// faces `ids`, and adds each covered pixel's colour gradient to its face's entry of
    /// `d_normals`, pixel by pixel in order. Implementations must give the bits of this default
    /// (one [`Seed::pixel`] call per pixel, in order); they exist to be cheaper.
    fn unblended(&mut self, start: usize, ids: &[u32], normals: &[DVec3], d_normals: &mut [DVec3]) {
        for (q, &id) in (start..).zip(ids) {
            let g = self.pixel(q, colour(normals, id));
            if id != BACKGROUND {
                d_normals[id as usize] += DVec3::new(g[0], g[1], g[2]);
            }
        }
    }
}

/// Whether all four channels are zero (either sign), without the slice comparison's loop.
#[inline]
fn is_zero(c: [f32; 4]) -> bool {
    (c[0] == 0.0) & (c[1] == 0.0) & (c[2] == 0.0) & (c[3] == 0.0)
}

/// Pixels tested at once for background over a zero target.
const BLANK_BLOCK: usize = 8;

/// Whether every pixel shows the background and every target channel is zero (either sign):
/// such pixels add no loss and no gradient. Takes [`BLANK_BLOCK`] pixels (shorter slices are
/// never blank); one OR over the bits (sign bits masked) instead of a branch per pixel.
#[inline]
fn is_blank(ids: &[u32], target: &[[f32; 4]]) -> bool {
    let (Ok(ids), Ok(target)) = (
        <&[u32; BLANK_BLOCK]>::try_from(ids),
        <&[[f32; 4]; BLANK_BLOCK]>::try_from(target),
    ) else {
        return false;
    };
    let mut any = 0u32;
    for k in 0..BLANK_BLOCK {
        any |= ids[k] ^ BACKGROUND;
        for c in target[k] {
            any |= c.to_bits() & 0x7fff_ffff;
        }
    }
    any == 0
}

/// A given image gradient (the unfused [`backward`]).
struct ImageSeed<'a> {
    d_image: &'a [[f64; 4]],
}

impl Seed for ImageSeed<'_> {
    fn pixel(&mut self, p: usize, _img: [f64; 4]) -> [f64; 4] {
        self.d_image[p]
    }
}

/// The image loss against a target image, summed into `loss` pixel by pixel and channel by
/// channel; `penalty(d) = (loss, dloss/dd)` per channel difference `d = I − T`, gradients
/// scaled by `inv_n` (the mean's `1/N`).
struct TargetSeed<'a, P> {
    target: &'a [[f32; 4]],
    inv_n: f64,
    penalty: P,
    loss: f64,
}

impl<P: Fn(f64) -> (f64, f64)> Seed for TargetSeed<'_, P> {
    fn pixel(&mut self, p: usize, img: [f64; 4]) -> [f64; 4] {
        let t = self.target[p];
        if img == [0.0; 4] && t == [0.0; 4] {
            // Background over background (a third of a typical view): no loss, no gradient.
            return [0.0; 4];
        }
        let mut g = [0.0; 4];
        for c in 0..4 {
            let (l, d) = (self.penalty)(img[c] - t[c] as f64);
            self.loss += l;
            g[c] = d * self.inv_n;
        }
        g
    }

    /// The default's arithmetic, in the same order, per run of equal ids: the colour is read
    /// once per run and the run's face-normal gradient is summed in a register (the same
    /// additions, in the same order, as adding into `d_normals` pixel by pixel). Background
    /// pixels skip the gradient, which the default discards.
    fn unblended(&mut self, start: usize, ids: &[u32], normals: &[DVec3], d_normals: &mut [DVec3]) {
        let target = &self.target[start..start + ids.len()];
        let mut loss = self.loss;
        let mut i = 0;
        while i < ids.len() {
            let id = ids[i];
            if id == BACKGROUND {
                while i < ids.len() && ids[i] == BACKGROUND {
                    if let (Some(block_ids), Some(block_target)) =
                        (ids.get(i..i + BLANK_BLOCK), target.get(i..i + BLANK_BLOCK))
                        && is_blank(block_ids, block_target)
                    {
                        i += BLANK_BLOCK;
                        continue;
                    }
                    let t = target[i];
                    i += 1;
                    if is_zero(t) {
                        continue;
                    }
                    for tc in t {
                        loss += (self.penalty)(0.0 - tc as f64).0;
                    }
                }
                continue;
            }
            let img = colour(normals, id);
            let mut acc = d_normals[id as usize];
            while i < ids.len() && ids[i] == id {
                let t = target[i];
                i += 1;
                let mut g = [0.0; 3];
                for c in 0..4 {
                    let (l, d) = (self.penalty)(img[c] - t[c] as f64);
                    loss += l;
                    if c < 3 {
                        g[c] = d * self.inv_n;
                    }
                }
                acc += DVec3::new(g[0], g[1], g[2]);
            }
            d_normals[id as usize] = acc;
        }
        self.loss = loss;
    }
}

/// Backward of one view given its `seed`. Every pixel is seeded once, in pixel order.
fn backward_view(
    geom: &ViewGeometry,
    cam: &Camera,
    normals: &[DVec3],
    seed: &mut impl Seed,
) -> ViewGrad {
    let m: DMat4 = cam.view_proj();
    let mut d_normals = vec![DVec3::ZERO; normals.len()];
    // At most two entries per item (its edge's endpoints), so the vector never regrows.
    let mut d_positions = Vec::with_capacity(2 * geom.items.len());
    let ids = &geom.ids;
    let items = &geom.items;
    let mut next = 0;
    let mut p = 0;
    while p < ids.len() {
        // Pixels up to the next AA target show their own face's colour unblended: the image
        // gradient goes to that face's normal only.
        let blended = items.get(next).map_or(ids.len(), |it| it.target as usize);
        seed.unblended(p, &ids[p..blended], normals, &mut d_normals);
        if blended == ids.len() {
            break;
        }
        p = blended;
        let start = next;
        while next < items.len() && items[next].target as usize == p {
            next += 1;
        }
        let pixel_items = &items[start..next];
        let id = ids[p];
        let base = colour(normals, id);
        let mut img = base;
        for it in pixel_items {
            let src = colour(normals, ids[it.source as usize]);
            for c in 0..4 {
                img[c] += it.alpha * (src[c] - base[c]);
            }
        }
        let g = seed.pixel(p, img);
        p += 1;
        if g == [0.0; 4] {
            continue;
        }
        let gn = DVec3::new(g[0], g[1], g[2]);
        let mut own = 1.0;
        for it in pixel_items {
            own -= it.alpha;
            let src_id = ids[it.source as usize];
            let src = colour(normals, src_id);
            if src_id != BACKGROUND {
                d_normals[src_id as usize] += gn * it.alpha;
            }
            let d_alpha: f64 = (0..4).map(|c| g[c] * (src[c] - base[c])).sum();
            let d_t = d_alpha * it.dalpha_dt;
            if d_t == 0.0 {
                continue;
            }
            let (front, other) = it.pixels();
            let [a, b] = it.edge;
            let (va, vb) = (&geom.verts[a as usize], &geom.verts[b as usize]);
            let dt = crossing_grad(
                [va.x, va.y],
                [vb.x, vb.y],
                pixel_centre(front, cam.width),
                pixel_centre(other, cam.width),
            );
            d_positions.push((
                a,
                project_backward(&m, cam.width, cam.height, va, d_t * dt[0], d_t * dt[1]),
            ));
            d_positions.push((
                b,
                project_backward(&m, cam.width, cam.height, vb, d_t * dt[2], d_t * dt[3]),
            ));
        }
        if id != BACKGROUND {
            d_normals[id as usize] += gn * own;
        }
    }
    ViewGrad {
        loss: 0.0,
        d_normals,
        d_positions,
    }
}

/// Renders `triangles` over `positions` from every camera.
///
/// Inputs: vertex positions (normalized into the rig's sphere), triangles as vertex index
/// triples (any soup: repeated, flipped or degenerate faces are fine), cameras. Output: per view
/// the id and depth buffers, the antialiased RGBA image and the AA items.
/// Errors: non-finite vertices, out-of-range indices, empty resolutions, vertices behind a
/// camera's near plane.
pub fn render(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    cameras: &[Camera],
    opts: &RenderOptions,
) -> Result<Renders, RenderError> {
    validate(positions, triangles, cameras)?;
    let neighbors = EdgeNeighbors::new(triangles);
    let normals = face_normals(positions, triangles);
    let views = cameras
        .par_iter()
        .enumerate()
        .map(|(ci, cam)| {
            let geom = forward_view(positions, triangles, &neighbors, cam, ci, opts)?;
            let mut rgba = Vec::with_capacity(geom.ids.len());
            shade_view(&geom.ids, &geom.items, &normals, |_, img, _| {
                rgba.push(img.map(|c| c as f32));
            });
            Ok(ViewRender {
                width: cam.width,
                height: cam.height,
                ids: geom.ids,
                depth: geom.depth,
                rgba,
                aa: geom.items,
            })
        })
        .collect::<Result<Vec<_>, RenderError>>()?;
    Ok(Renders {
        views,
        num_faces: triangles.len(),
    })
}

/// Sums per-view gradients in view order and back-propagates the face-normal gradients once.
fn reduce_views(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    num_views: usize,
    per_view: impl Fn(usize) -> Result<ViewGrad, RenderError> + Sync,
) -> Result<(f64, Vec<DVec3>), RenderError> {
    let mut loss = 0.0;
    let mut d_normals = vec![DVec3::ZERO; triangles.len()];
    let mut grad = vec![DVec3::ZERO; positions.len()];
    let mut aa_grads = Vec::new();
    let indices: Vec<usize> = (0..num_views).collect();
    for chunk in indices.chunks(VIEW_CHUNK) {
        let results = chunk
            .par_iter()
            .map(|&v| per_view(v))
            .collect::<Result<Vec<_>, RenderError>>()?;
        for r in results {
            loss += r.loss;
            for (acc, d) in d_normals.iter_mut().zip(&r.d_normals) {
                *acc += *d;
            }
            aa_grads.push(r.d_positions);
        }
    }
    for (t, &g_n) in triangles.iter().zip(&d_normals) {
        if g_n == DVec3::ZERO {
            continue;
        }
        let [i0, i1, i2] = t.map(|i| i as usize);
        let g = face_normal_backward(positions[i0], positions[i1], positions[i2], g_n);
        grad[i0] += g[0];
        grad[i1] += g[1];
        grad[i2] += g[2];
    }
    for view in aa_grads {
        for (v, g) in view {
            grad[v as usize] += g;
        }
    }
    Ok((loss, grad))
}

/// Backward pass of [`render`]: given `dL/dI` per view and pixel (RGBA), returns `dL/dV` per
/// vertex, through the face normals of covered pixels and through the antialiasing crossings of
/// silhouette and occlusion edges. `renders` must come from [`render`] with the same inputs.
pub fn backward(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    cameras: &[Camera],
    renders: &Renders,
    d_image: &[Vec<[f64; 4]>],
) -> Result<Vec<DVec3>, RenderError> {
    validate(positions, triangles, cameras)?;
    if renders.views.len() != cameras.len() || d_image.len() != cameras.len() {
        return Err(RenderError::ShapeMismatch {
            what: format!(
                "{} cameras, {} renders, {} image gradients",
                cameras.len(),
                renders.views.len(),
                d_image.len()
            ),
        });
    }
    for (i, (view, cam)) in renders.views.iter().zip(cameras).enumerate() {
        if view.ids.len() != cam.num_pixels() || d_image[i].len() != cam.num_pixels() {
            return Err(RenderError::ShapeMismatch {
                what: format!("view {i}: buffer sizes differ from the camera's resolution"),
            });
        }
    }
    let normals = face_normals(positions, triangles);
    let (_, grad) = reduce_views(positions, triangles, cameras.len(), |v| {
        let cam = &cameras[v];
        let view = &renders.views[v];
        let geom = ViewGeometry {
            verts: project_view(positions, cam, v)?,
            ids: view.ids.clone(),
            depth: Vec::new(),
            items: view.aa.clone(),
        };
        let mut seed = ImageSeed {
            d_image: &d_image[v],
        };
        Ok(backward_view(&geom, cam, &normals, &mut seed))
    })?;
    Ok(grad)
}

/// The fused path the optimizer uses: renders every view, compares it with `targets` (one image
/// per camera), and returns the mean image loss and `dL/dV`, without keeping any view's buffers
/// after it is done. Colours, blends and gradients are computed in f64 (targets are f32).
pub fn render_loss_and_grad(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    cameras: &[Camera],
    targets: &[Image],
    opts: &RenderOptions,
    kind: LossKind,
) -> Result<(f64, Vec<DVec3>), RenderError> {
    validate(positions, triangles, cameras)?;
    if targets.len() != cameras.len() {
        return Err(RenderError::ShapeMismatch {
            what: format!("{} cameras but {} targets", cameras.len(), targets.len()),
        });
    }
    for (i, (t, cam)) in targets.iter().zip(cameras).enumerate() {
        if t.len() != cam.num_pixels() {
            return Err(RenderError::ShapeMismatch {
                what: format!(
                    "target {i} has {} pixels, camera {}",
                    t.len(),
                    cam.num_pixels()
                ),
            });
        }
    }
    let total: usize = cameras.iter().map(|c| c.num_pixels() * 4).sum();
    let inv_n = if total > 0 { 1.0 / total as f64 } else { 0.0 };
    let neighbors = EdgeNeighbors::new(triangles);
    let normals = face_normals(positions, triangles);
    let (loss, grad) = reduce_views(positions, triangles, cameras.len(), |v| {
        let cam = &cameras[v];
        let geom = forward_view(positions, triangles, &neighbors, cam, v, opts)?;
        let target = &targets[v];
        // One copy of the per-pixel loop per loss, so the penalty inlines without a branch.
        Ok(match kind {
            LossKind::L1 => view_loss_and_grad(&geom, cam, &normals, target, inv_n, |d| {
                loss_term(LossKind::L1, d)
            }),
            LossKind::L2 => view_loss_and_grad(&geom, cam, &normals, target, inv_n, |d| {
                loss_term(LossKind::L2, d)
            }),
        })
    })?;
    Ok((loss * inv_n, grad))
}

/// Loss and gradient of one view against its target image, `penalty(d) = (loss, dloss/dd)`
/// per channel difference `d = I − T` (before the mean's `inv_n`).
fn view_loss_and_grad(
    geom: &ViewGeometry,
    cam: &Camera,
    normals: &[DVec3],
    target: &[[f32; 4]],
    inv_n: f64,
    penalty: impl Fn(f64) -> (f64, f64),
) -> ViewGrad {
    let mut seed = TargetSeed {
        target,
        inv_n,
        penalty,
        loss: 0.0,
    };
    let mut r = backward_view(geom, cam, normals, &mut seed);
    r.loss = seed.loss;
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`TargetSeed`] with the trait's default `unblended`, the reference for its override.
    struct PerPixel<'a, P>(TargetSeed<'a, P>);

    impl<P: Fn(f64) -> (f64, f64)> Seed for PerPixel<'_, P> {
        fn pixel(&mut self, p: usize, img: [f64; 4]) -> [f64; 4] {
            self.0.pixel(p, img)
        }
    }

    /// Tiny deterministic generator (xorshift) in [0, 1).
    fn next(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn blank_blocks_are_background_over_zero_targets() {
        let ids = [BACKGROUND; BLANK_BLOCK];
        let zero = [[0.0f32; 4]; BLANK_BLOCK];
        assert!(is_blank(&ids, &zero));
        let mut signed = zero;
        signed[3] = [-0.0, 0.0, -0.0, -0.0];
        assert!(is_blank(&ids, &signed));
        assert!(!is_blank(&ids[1..], &zero[1..]));
        for k in 0..BLANK_BLOCK {
            let mut covered = ids;
            covered[k] = 0;
            assert!(!is_blank(&covered, &zero));
            for (c, value) in [(0, 1e-40), (3, -1.0), (2, f32::NAN)] {
                let mut target = zero;
                target[k][c] = value;
                assert!(!is_blank(&ids, &target), "{k} {c}");
            }
        }
    }

    #[test]
    fn run_seeding_gives_the_bits_of_per_pixel_seeding() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let normals: Vec<DVec3> = (0..5)
            .map(|_| DVec3::new(next(&mut state), next(&mut state), next(&mut state)) - 0.5)
            .collect();
        for case in 0..50 {
            // Runs of faces and background (long enough for blank blocks), targets zero (most
            // of the background), equal to the rendered colour, or random.
            let n = 1 + case * 7;
            let mut ids = Vec::new();
            while ids.len() < n {
                let id = match (next(&mut state) * 7.0) as u32 {
                    k @ 0..=4 => k,
                    _ => BACKGROUND,
                };
                let len = 1 + (next(&mut state) * 20.0) as usize;
                ids.extend(std::iter::repeat_n(id, len));
            }
            ids.truncate(n);
            let target: Vec<[f32; 4]> = ids
                .iter()
                .map(|&id| match (next(&mut state) * 3.0) as u32 {
                    _ if id == BACKGROUND && next(&mut state) < 0.8 => [0.0; 4],
                    0 => [0.0; 4],
                    1 => colour(&normals, id).map(|c| c as f32),
                    _ => [0; 4].map(|_| next(&mut state) as f32 - 0.5),
                })
                .collect();
            let start = case % 3;
            let target = [vec![[0.25; 4]; start], target].concat();
            for kind in [LossKind::L1, LossKind::L2] {
                let penalty = |d| loss_term(kind, d);
                let seed = |loss| TargetSeed {
                    target: &target,
                    inv_n: 1.0 / 3.0,
                    penalty,
                    loss,
                };
                let initial: Vec<DVec3> = normals.iter().map(|n| *n * 0.1).collect();
                let (mut runs, mut per_pixel) = (seed(0.5), PerPixel(seed(0.5)));
                let (mut d_runs, mut d_pixels) = (initial.clone(), initial);
                runs.unblended(start, &ids, &normals, &mut d_runs);
                per_pixel.unblended(start, &ids, &normals, &mut d_pixels);
                assert_eq!(runs.loss.to_bits(), per_pixel.0.loss.to_bits(), "{case}");
                let bits = |d: &[DVec3]| -> Vec<[u64; 3]> {
                    d.iter().map(|v| v.to_array().map(f64::to_bits)).collect()
                };
                assert_eq!(bits(&d_runs), bits(&d_pixels), "case {case} {kind:?}");
            }
        }
    }
}
