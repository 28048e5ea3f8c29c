//! `roar decimate INPUT -o OUTPUT --faces N [--best-effort] [--reduce-genus]`: the guaranteed
//! QEM. The input must be a closed 2-manifold; the output keeps its genus and components, has
//! exactly N faces and no new self-intersections, or the command fails saying how close it got.
//! With `--reduce-genus` handles are removed (shortest loop first, `roar_ops::genus`) when the
//! genus needs more faces than N or the QEM stalls; components are still kept.

use std::path::PathBuf;

use clap::Args;
use roar_ops::genus::{HandleRemovalOptions, decimate_removing_handles};
use roar_ops::qem::{DecimateOptions, decimate_in_parallel};

use crate::input::{read_closed_mesh, write_mesh};

/// Arguments of `roar decimate`.
#[derive(Args, Debug)]
pub struct DecimateArgs {
    /// A closed, oriented 2-manifold mesh (bit-identical positions are welded first).
    pub input: PathBuf,
    /// Where to write the result (format by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The exact face count to reach (even).
    #[arg(long)]
    pub faces: usize,
    /// When the vetoes block the budget, write the closest mesh instead of failing.
    #[arg(long)]
    pub best_effort: bool,
    /// Remove handles (shortest loop first) when the genus needs more faces than N or the
    /// decimation stalls, instead of failing.
    #[arg(long)]
    pub reduce_genus: bool,
}

/// Runs `roar decimate`.
pub fn run(args: &DecimateArgs) -> anyhow::Result<()> {
    let mut mesh = read_closed_mesh(&args.input)?;
    let options = DecimateOptions {
        best_effort: args.best_effort,
        ..DecimateOptions::default()
    };
    let stats = if args.reduce_genus {
        let (stats, removed) = decimate_removing_handles(
            &mut mesh,
            args.faces,
            &options,
            &HandleRemovalOptions::default(),
            decimate_in_parallel,
        )?;
        for handle in &removed {
            eprintln!(
                "note: removed a handle (cut along a loop of {} edges, length {:.4})",
                handle.loop_vertices, handle.loop_length
            );
        }
        stats
    } else {
        decimate_in_parallel(&mut mesh, args.faces, &options)?
    };
    write_mesh(&args.output, &mesh)?;
    if stats.reached_target {
        eprintln!(
            "wrote {} ({} faces, from {})",
            args.output.display(),
            mesh.n_faces(),
            stats.initial_faces
        );
    } else {
        eprintln!(
            "wrote {} with {} faces: the budget {} was not reached (best effort)",
            args.output.display(),
            mesh.n_faces(),
            args.faces
        );
    }
    Ok(())
}
