//! `roar extract FIELD -o OUTPUT --resolution R [--bounds …]`: the marching baseline of an SDF
//! input. Samples the field on a grid of R points along the longest side of the bounds and
//! writes the zero set by marching tetrahedra, a closed, oriented 2-manifold (`roar decimate`
//! brings it to a budget). Prints one JSON line: the grid, the field's evaluations (values and
//! gradients), the seconds and the face count.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use roar_io::TriangleSoup;
use roar_mesh::spatial::Aabb;
use roar_sdf::{DEFAULT_BOUNDS, ExtractOptions, extract_zero_set};
use serde::Serialize;

use crate::checks::check_paths;

/// Arguments of `roar extract`.
#[derive(Args, Debug)]
pub struct ExtractArgs {
    /// A signed distance function: `.npz`, `.safetensors`, `.sdf.toml` or `.npy` (with its `.json` sidecar).
    pub input: PathBuf,
    /// Where to write the zero set (format by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Samples along the longest side of the bounds (2 to 2048).
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=2048))]
    pub resolution: u32,
    /// Box to sample, `xmin,ymin,zmin,xmax,ymax,zmax` (default: a grid's sidecar bounds, else
    /// `-1.1,-1.1,-1.1,1.1,1.1,1.1`), as for `roar reconstruct`.
    #[arg(long, value_parser = super::reconstruct::parse_bounds, allow_hyphen_values = true)]
    pub bounds: Option<Aabb>,
    /// Print the costs as one JSON line on stdout (grid, evaluations, seconds, counts) instead
    /// of the summary.
    #[arg(long)]
    pub json: bool,
}

/// The JSON line `roar extract` prints.
#[derive(Serialize)]
struct ExtractReport {
    dims: [usize; 3],
    values: u64,
    gradients: u64,
    seconds_sampling: f64,
    seconds_marching: f64,
    seconds_total: f64,
    vertices: usize,
    faces: usize,
}

/// Runs `roar extract`. Errors before any work: unreadable field, input and output the same
/// file; after: a zero set with no face inside the bounds. Nothing is written on error.
pub fn run(args: &ExtractArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    check_paths(&[("INPUT", &args.input)], &[("-o", &args.output)])?;
    let loaded = roar_sdf::load_sdf_input(&args.input, args.bounds.unwrap_or(DEFAULT_BOUNDS))
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.input.display()))?;
    let bounds = args.bounds.or(loaded.bounds).unwrap_or(DEFAULT_BOUNDS);
    let options = ExtractOptions {
        resolution: args.resolution as usize,
    };
    let (positions, triangles, stats) = extract_zero_set(loaded.field.as_ref(), &bounds, &options);
    if triangles.is_empty() {
        anyhow::bail!(
            "{}: the field has no zero set inside the bounds at resolution {}",
            args.input.display(),
            args.resolution
        );
    }
    let evaluations = loaded.field.evaluations();
    let report = ExtractReport {
        dims: stats.dims,
        values: evaluations.values,
        gradients: evaluations.gradients,
        seconds_sampling: stats.seconds_sampling,
        seconds_marching: stats.seconds_marching,
        seconds_total: 0.0,
        vertices: positions.len(),
        faces: triangles.len(),
    };
    roar_io::write_mesh(&args.output, &TriangleSoup::new(positions, triangles))
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    let report = ExtractReport {
        seconds_total: started.elapsed().as_secs_f64(),
        ..report
    };
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!(
            "wrote {} ({} faces, grid {}x{}x{}, {} evaluations) in {:.1} s",
            args.output.display(),
            report.faces,
            report.dims[0],
            report.dims[1],
            report.dims[2],
            report.values + report.gradients,
            report.seconds_total
        );
    }
    Ok(())
}
