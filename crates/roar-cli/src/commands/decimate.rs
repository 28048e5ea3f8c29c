//! `roar decimate INPUT -o OUTPUT --faces N [--best-effort] [--reduce-genus]`: the guaranteed
//! QEM. The input must be a closed 2-manifold; the output keeps its genus and components, has
//! exactly N faces and no new self-intersections, or the command fails saying how close it got.
//! With `--reduce-genus` handles are removed as the reconstruction's finish removes them
//! (`roar_ops::finish::exact_budget`: shortest loop first, the crossings of each cut untangled)
//! when the genus needs more faces than N or the QEM stalls; components are still kept.

use std::path::PathBuf;

use clap::Args;
use roar_ops::decimate::{DecimateOptions, decimate_in_parallel};
use roar_ops::finish::exact_budget::{ExactBudgetOptions, decimate_to_exact_budget};
use roar_ops::untangle::UntangleOptions;

use crate::checks::check_paths;
use crate::mesh_files::{parse_faces, read_closed_mesh, write_mesh};
use roar::budget::{check_budget, smallest_budget};

/// Arguments of `roar decimate`.
#[derive(Args, Debug)]
pub struct DecimateArgs {
    /// A closed, oriented 2-manifold mesh (bit-identical positions are welded first).
    pub input: PathBuf,
    /// Where to write the result (format by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The exact face count to reach (even, at most the input's).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_faces)]
    pub faces: usize,
    /// When the vetoes block the budget, write the closest mesh instead of failing (the exit
    /// status is 0 and the message says how close it got).
    #[arg(long)]
    pub best_effort: bool,
    /// Remove handles (shortest loop first) when the genus needs more faces than N or the
    /// decimation stalls, instead of failing.
    #[arg(long)]
    pub reduce_genus: bool,
}

/// Runs `roar decimate`.
///
/// Errors before any work: input and output the same file, an output that cannot be written, a
/// budget that is odd, below what the input's pieces and genera allow, or above the input's
/// face count (decimation only removes faces). After the decimation: the budget was not reached
/// (unless `--best-effort`), naming how close it got and why.
pub fn run(args: &DecimateArgs) -> anyhow::Result<()> {
    check_paths(&[("INPUT", &args.input)], &[("-o", &args.output)])?;
    let mut mesh = read_closed_mesh(&args.input)?;
    let minimum = smallest_budget(&mesh.component_genera(), !args.reduce_genus);
    check_budget("--faces", args.faces, minimum)?;
    if args.faces > mesh.n_faces() {
        anyhow::bail!(
            "--faces {} is above the {} faces of {}: decimation only removes faces \
             (`roar reconstruct` refines a mesh to any budget)",
            args.faces,
            mesh.n_faces(),
            args.input.display()
        );
    }
    let options = ExactBudgetOptions {
        decimate: DecimateOptions {
            best_effort: args.best_effort,
            ..DecimateOptions::default()
        },
        keep_topology: !args.reduce_genus,
        untangle: UntangleOptions::default(),
    };
    let reached = decimate_to_exact_budget(&mut mesh, args.faces, &options, decimate_in_parallel)?;
    for handle in &reached.handles_removed {
        eprintln!(
            "note: removed a handle (cut along a loop of {} edges, length {:.4})",
            handle.loop_vertices, handle.loop_length
        );
    }
    let stats = reached.decimate;
    let reached = mesh.n_faces() == args.faces;
    write_mesh(&args.output, &mesh)?;
    if reached {
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
