//! `roar render MESH -o DIR [--views N] [--res R]`: what the optimizer sees. Normalizes the mesh
//! into the rig's sphere (radius 0.95), renders flat normal maps from the star rig and writes
//! `view_00.png`, … plus `cameras.json`, so a third party can check the images.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Args;
use roar_mesh::spatial::Normalization;
use roar_render::{RenderOptions, star_cameras};
use serde::Serialize;

/// Arguments of `roar render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The mesh to render (any soup).
    pub mesh: PathBuf,
    /// Output folder (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Number of views, a square k²: k azimuths × k polar angles.
    #[arg(long, default_value_t = 36)]
    pub views: usize,
    /// Image width and height in pixels.
    #[arg(long, default_value_t = 512)]
    pub res: u32,
    /// Cull faces seen from behind (as the target clean-up does).
    #[arg(long)]
    pub cull_backfaces: bool,
    /// Also write each view as a float EXR (`view_00.exr`, …).
    #[arg(long)]
    pub exr: bool,
}

/// One camera in `cameras.json`.
#[derive(Serialize)]
struct CameraRecord {
    image: String,
    width: u32,
    height: u32,
    /// World (normalized) → camera, row-major.
    view: [[f64; 4]; 4],
    /// Camera → clip (OpenGL convention, y flipped), row-major.
    projection: [[f64; 4]; 4],
}

/// `cameras.json`: the normalization and every camera.
#[derive(Serialize)]
struct CamerasFile {
    /// `p_normalized = (p − center) · scale`.
    normalization_center: [f64; 3],
    /// See `normalization_center`.
    normalization_scale: f64,
    cameras: Vec<CameraRecord>,
}

/// Runs `roar render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    let k = (args.views as f64).sqrt().round() as usize;
    if k == 0 || k * k != args.views {
        bail!(
            "--views must be a square number k² (k azimuths × k polar angles), got {}",
            args.views
        );
    }
    if args.res == 0 || args.res > 8192 {
        bail!("--res must be between 1 and 8192, got {}", args.res);
    }
    let soup = roar_io::read_mesh(&args.mesh)?;
    let normalization =
        Normalization::fit(&soup.positions, &soup.triangles).with_context(|| {
            format!(
                "{}: the mesh has no extent to normalize",
                args.mesh.display()
            )
        })?;
    let mut positions = soup.positions.clone();
    normalization.apply_all(&mut positions);
    let cameras = star_cameras(k, k, args.res, args.res);
    let options = RenderOptions {
        cull_backfaces: args.cull_backfaces,
        ..RenderOptions::default()
    };
    let renders = roar_render::render(&positions, &soup.triangles, &cameras, &options)?;

    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create {}", args.output.display()))?;
    let mut records = Vec::with_capacity(cameras.len());
    for (index, (camera, view)) in cameras.iter().zip(&renders.views).enumerate() {
        let name = format!("view_{index:02}.png");
        let rgba8 = roar_render::to_rgba8(&view.rgba);
        roar_io::write_png_rgba8(&args.output.join(&name), view.width, view.height, &rgba8)?;
        if args.exr {
            let exr = args.output.join(format!("view_{index:02}.exr"));
            roar_io::write_exr_rgba(&exr, view.width, view.height, &view.rgba)?;
        }
        records.push(CameraRecord {
            image: name,
            width: camera.width,
            height: camera.height,
            view: camera.view_matrix_row_major(),
            projection: camera.proj_matrix_row_major(),
        });
    }
    let file = CamerasFile {
        normalization_center: normalization.center.to_array(),
        normalization_scale: normalization.scale,
        cameras: records,
    };
    let json = serde_json::to_string_pretty(&file)?;
    roar_io::atomic_write(&args.output.join("cameras.json"), |w| {
        w.write_all(json.as_bytes())
    })?;
    eprintln!(
        "wrote {} views and cameras.json to {}",
        cameras.len(),
        args.output.display()
    );
    Ok(())
}
