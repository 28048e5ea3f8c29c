//! The preview picture of a reconstruction (`roar reconstruct … --preview preview.png`): the
//! input (top row) and the output (bottom row) shaded from the same four views, the output with
//! its wireframe, and under them the loss curve of the run.
//!
//! The input is a soup (a scan set's aligned patches are one) or views of it already rendered
//! by [`preview_cameras`] (an SDF's traced zero set, [`PreviewInput::Views`]). Both rows are
//! framed by one normalization (the soup's own, or the SDF's rig), so they line up tile for
//! tile; meshes are rendered by roar's own rasterizer (`roar_render::render`, both sides, no
//! antialiasing); shading is a headlight: brightness `0.25 + 0.75·|n·d|` for face normal `n` and viewing
//! direction `d`, so the inward faces of a soup show as well as outward ones. Wire edges are
//! drawn where they are not hidden by the surface (a small depth tolerance). The curve panel
//! plots log10 of the loss per iteration, scaled from its minimum (bottom) to its maximum (top);
//! it carries no text.

use std::path::Path;

use anyhow::Context;
use glam::DVec3;
use roar_mesh::spatial::Normalization;
use roar_render::{BACKGROUND, Camera, Image, RenderOptions, star_cameras};

/// What the input row of the picture shows.
#[derive(Debug, Clone, Copy)]
pub enum PreviewInput<'a> {
    /// A soup (any coordinates), rendered here and framed by its own normalization.
    Soup(&'a [DVec3], &'a [[u32; 3]]),
    /// Four normal maps of the input already rendered by [`preview_cameras`] at the picture's
    /// tile size in the rig coordinates of `normalization` (a pixel is the surface where its
    /// alpha is positive); the output is framed by the same `normalization`.
    Views {
        /// Input coordinates to rig coordinates.
        normalization: Normalization,
        /// One normal map per camera of [`preview_cameras`], `tile²` pixels each.
        views: &'a [Image],
    },
}

/// Options of [`preview_image`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreviewOptions {
    /// Width and height of one view tile in pixels.
    pub tile: u32,
}

impl Default for PreviewOptions {
    fn default() -> Self {
        Self { tile: 320 }
    }
}

/// An 8-bit RGBA picture, row by row from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct PreviewImage {
    /// Width in pixels (4 tiles).
    pub width: u32,
    /// Height in pixels (3 tiles: input, output, loss curve).
    pub height: u32,
    /// `width · height · 4` bytes.
    pub rgba: Vec<u8>,
}

/// Colours of the picture.
const BACKGROUND_RGB: [u8; 3] = [255, 255, 255];
const INPUT_RGB: [f64; 3] = [120.0, 150.0, 200.0];
const OUTPUT_RGB: [f64; 3] = [230.0, 160.0, 90.0];
/// Wire edges of the output, and the loss curve.
pub const WIRE_RGB: [u8; 3] = [40, 40, 40];
const AXIS_RGB: [u8; 3] = [160, 160, 160];

/// The four views of a picture with tiles of `tile` pixels: azimuths 0°, 90°, 180°, 270° at the
/// rig's upper polar angle (30° above the equator).
pub fn preview_cameras(tile: u32) -> Vec<Camera> {
    let all = star_cameras(4, 2, tile, tile);
    (0..4).map(|a| all[a * 2 + 1]).collect()
}

/// The picture of `input` and `output` (plain buffers, any coordinates) and of `losses` (one
/// per iteration; non-finite values are skipped; an empty slice leaves the panel blank).
///
/// Errors: the input soup has no extent to frame, the input views are not four of `tile²`
/// pixels, or a mesh cannot be rendered (indices out of range, non-finite coordinates).
pub fn preview_image(
    input: PreviewInput<'_>,
    output: (&[DVec3], &[[u32; 3]]),
    losses: &[f64],
    options: &PreviewOptions,
) -> anyhow::Result<PreviewImage> {
    let tile = options.tile.max(16);
    let cameras = preview_cameras(tile);
    let (width, height) = (4 * tile, 3 * tile);
    let mut canvas = Canvas::new(width, height);
    let normalization = match input {
        PreviewInput::Soup(positions, triangles) => {
            let normalization = Normalization::fit(positions, triangles)
                .context("the input has no extent to frame")?;
            let mut normalized = positions.to_vec();
            normalization.apply_all(&mut normalized);
            let (views, _) = render_views(&normalized, triangles, &cameras)?;
            shade_row(&mut canvas, 0, &cameras, &views, INPUT_RGB);
            normalization
        }
        PreviewInput::Views {
            normalization,
            views,
        } => {
            let pixels = (tile * tile) as usize;
            anyhow::ensure!(
                views.len() == cameras.len() && views.iter().all(|v| v.len() == pixels),
                "the preview needs {} input views of {tile}×{tile} pixels",
                cameras.len()
            );
            shade_row(&mut canvas, 0, &cameras, views, INPUT_RGB);
            normalization
        }
    };
    let mut normalized = output.0.to_vec();
    normalization.apply_all(&mut normalized);
    let (views, depths) = render_views(&normalized, output.1, &cameras)?;
    shade_row(&mut canvas, 1, &cameras, &views, OUTPUT_RGB);
    for (column, (camera, depth)) in cameras.iter().zip(&depths).enumerate() {
        draw_wireframe(
            &mut canvas,
            (column as u32 * tile, tile),
            camera,
            depth,
            &normalized,
            output.1,
        );
    }
    draw_curve(&mut canvas, (0, 2 * tile), (width, tile), losses);
    Ok(PreviewImage {
        width,
        height,
        rgba: canvas.rgba,
    })
}

/// The normal maps (alpha 1 on the surface, 0 elsewhere) and NDC depth buffers of the cameras'
/// views of the mesh (rig coordinates).
fn render_views(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    cameras: &[Camera],
) -> anyhow::Result<(Vec<Image>, Vec<Vec<f32>>)> {
    let render_options = RenderOptions {
        cull_backfaces: false,
        antialias: false,
    };
    let renders = roar_render::render(positions, triangles, cameras, &render_options)
        .context("cannot render the preview")?;
    Ok(renders
        .views
        .into_iter()
        .map(|view| {
            let rgba = view
                .rgba
                .iter()
                .zip(&view.ids)
                .map(|(px, &id)| {
                    let alpha = if id == BACKGROUND { 0.0 } else { 1.0 };
                    [px[0], px[1], px[2], alpha]
                })
                .collect();
            (rgba, view.depth)
        })
        .unzip())
}

/// Shades the normal maps `views` (one per camera) into picture row `row` with a headlight.
fn shade_row(canvas: &mut Canvas, row: u32, cameras: &[Camera], views: &[Image], colour: [f64; 3]) {
    for (column, (camera, rgba)) in cameras.iter().zip(views).enumerate() {
        let tile = camera.width;
        let origin = (column as u32 * tile, row * tile);
        let towards = -camera.position().normalize();
        for (i, px) in rgba.iter().enumerate() {
            if px[3] <= 0.0 {
                continue;
            }
            let n = DVec3::new(px[0] as f64, px[1] as f64, px[2] as f64);
            let light = 0.25 + 0.75 * n.normalize_or_zero().dot(towards).abs();
            let rgb = colour.map(|c| (c * light).round().clamp(0.0, 255.0) as u8);
            let (x, y) = (i as u32 % tile, i as u32 / tile);
            canvas.put(origin.0 + x, origin.1 + y, rgb);
        }
    }
}

/// Computes the picture and writes it as PNG (atomically). See [`preview_image`].
pub fn write_preview(
    path: &Path,
    input: PreviewInput<'_>,
    output: (&[DVec3], &[[u32; 3]]),
    losses: &[f64],
    options: &PreviewOptions,
) -> anyhow::Result<()> {
    let image = preview_image(input, output, losses, options)?;
    roar_io::write_png_rgba8(path, image.width, image.height, &image.rgba)?;
    Ok(())
}

/// An opaque RGBA canvas filled with the background colour.
struct Canvas {
    width: u32,
    height: u32,
    rgba: Vec<u8>,
}

impl Canvas {
    fn new(width: u32, height: u32) -> Self {
        let mut rgba = Vec::with_capacity(width as usize * height as usize * 4);
        for _ in 0..width as usize * height as usize {
            rgba.extend_from_slice(&[BACKGROUND_RGB[0], BACKGROUND_RGB[1], BACKGROUND_RGB[2], 255]);
        }
        Self {
            width,
            height,
            rgba,
        }
    }

    fn put(&mut self, x: u32, y: u32, rgb: [u8; 3]) {
        if x < self.width && y < self.height {
            let at = (y as usize * self.width as usize + x as usize) * 4;
            self.rgba[at..at + 3].copy_from_slice(&rgb);
        }
    }
}

/// Draws every edge of the mesh into the tile at `origin`, pixel by pixel, where the edge is
/// not behind the rendered surface (`depth`: the tile's NDC depth buffer).
fn draw_wireframe(
    canvas: &mut Canvas,
    origin: (u32, u32),
    camera: &Camera,
    depth: &[f32],
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) {
    let tile = camera.width;
    let projected: Vec<_> = positions.iter().map(|&p| camera.project(p)).collect();
    // Tolerance in NDC depth: the rig's depth range is compressed near z = 1.
    let tolerance = 2e-4;
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            // In a closed mesh every edge appears once in each direction: draw it once.
            if a > b {
                continue;
            }
            let (p, q) = (projected[a as usize], projected[b as usize]);
            let steps = ((q.x - p.x).abs().max((q.y - p.y).abs()).ceil() as usize).max(1);
            for s in 0..=steps {
                let u = s as f64 / steps as f64;
                let (x, y, z) = (
                    p.x + (q.x - p.x) * u,
                    p.y + (q.y - p.y) * u,
                    p.z + (q.z - p.z) * u,
                );
                if x < 0.0 || y < 0.0 || x >= tile as f64 || y >= tile as f64 {
                    continue;
                }
                let (px, py) = (x as u32, y as u32);
                let surface = depth[(py * tile + px) as usize] as f64;
                if z <= surface + tolerance {
                    canvas.put(origin.0 + px, origin.1 + py, WIRE_RGB);
                }
            }
        }
    }
}

/// The loss curve (log10, min at the bottom, max at the top) in the panel at `origin` of `size`,
/// inside a frame.
fn draw_curve(canvas: &mut Canvas, origin: (u32, u32), size: (u32, u32), losses: &[f64]) {
    let margin = size.1 / 10;
    let (x0, y0) = (origin.0 + margin, origin.1 + margin);
    let (w, h) = (size.0 - 2 * margin, size.1 - 2 * margin);
    for x in x0..=x0 + w {
        canvas.put(x, y0 + h, AXIS_RGB);
    }
    for y in y0..=y0 + h {
        canvas.put(x0, y, AXIS_RGB);
    }
    let points: Vec<(usize, f64)> = losses
        .iter()
        .enumerate()
        .filter(|(_, l)| l.is_finite() && **l > 0.0)
        .map(|(i, l)| (i, l.log10()))
        .collect();
    let Some(&(last, _)) = points.last() else {
        return;
    };
    let lo = points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    let span = if hi > lo { hi - lo } else { 1.0 };
    let to_pixel = |(i, v): (usize, f64)| {
        let x = x0 as f64 + w as f64 * i as f64 / last.max(1) as f64;
        let y = (y0 + h) as f64 - h as f64 * (v - lo) / span;
        (x, y)
    };
    for pair in points.windows(2) {
        let (a, b) = (to_pixel(pair[0]), to_pixel(pair[1]));
        let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).max(1);
        for s in 0..=steps {
            let u = s as f64 / steps as f64;
            let (x, y) = (a.0 + (b.0 - a.0) * u, a.1 + (b.1 - a.1) * u);
            // Two pixels thick, so the curve reads at a glance.
            canvas.put(x as u32, y as u32, WIRE_RGB);
            canvas.put(x as u32, y as u32 + 1, WIRE_RGB);
        }
    }
}
