//! `roar init INPUT -o OUTPUT [--resolution R] [--faces N]`: the watertight, outward-oriented,
//! 2-manifold, self-intersection-free mesh of any soup (voxelize, close gaps, flood fill, manifold
//! boundary, projection), decimated to at most N faces.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use roar_ops::init::{InitOptions, InitialMeshOptions, initial_mesh};

use crate::mesh_files::write_mesh;
use roar::budget::check_even_budget;
use roar::input::welded_referenced;

/// Arguments of `roar init`.
#[derive(Args, Debug)]
pub struct InitArgs {
    /// Any triangle soup (OBJ, PLY, STL or OFF).
    pub input: PathBuf,
    /// Where to write the closed mesh (format by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Voxels along the longest bounding-box axis.
    #[arg(long, default_value_t = InitOptions::default().resolution)]
    pub resolution: usize,
    /// Decimate to at most this many faces (even); the voxel surface itself is much finer.
    #[arg(long, default_value_t = 20_000)]
    pub faces: usize,
}

/// Runs `roar init`.
pub fn run(args: &InitArgs) -> anyhow::Result<()> {
    check_even_budget(args.faces)?;
    crate::checks::check_paths(&[("INPUT", &args.input)], &[("-o", &args.output)])?;
    let soup = roar_io::read_mesh(&args.input)?;
    let (positions, triangles) = welded_referenced(&soup);
    let options = InitialMeshOptions {
        init: InitOptions {
            resolution: args.resolution,
            ..InitOptions::default()
        },
        max_faces: args.faces,
        ..InitialMeshOptions::default()
    };
    let (mesh, stats) = initial_mesh(&positions, &triangles, &options)
        .with_context(|| format!("{}: watertight init failed", args.input.display()))?;
    write_mesh(&args.output, &mesh)?;
    eprintln!(
        "wrote {}: {} faces ({} before decimation), {} piece(s), {} dropped, genus {}, {} voxels \
         closed by the winding number",
        args.output.display(),
        mesh.n_faces(),
        stats.init_faces,
        stats.init.pieces,
        stats.init.dropped_pieces,
        mesh.genus(),
        stats.init.voxels_filled_by_winding
    );
    Ok(())
}
