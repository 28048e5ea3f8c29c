//! The `roar` command line: a thin clap front end over `roar_cli::commands`.
//!
//! Every failure is one line on stderr (`roar: error: …`) and a non-zero exit; nothing is written
//! to an output path unless the whole job succeeded (writers are atomic).

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use roar_cli::commands;

/// Clean, closed, budgeted triangle meshes from messy 3D shapes.
#[derive(Parser)]
#[command(name = "roar", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Reconstruct a closed, oriented 2-manifold with exactly N faces and no self-intersections
    /// from any soup (the ROAR pipeline).
    Reconstruct(commands::reconstruct::ReconstructArgs),
    /// Vertex and face counts, bounding box, and whether the mesh is a closed 2-manifold
    /// (its genus and components if so, the first reason it is not otherwise).
    Info(commands::info::InfoArgs),
    /// Every metric of a mesh (topology, quality, self-intersections, orientation) and, with
    /// `--ref`, its fidelity to a reference (Chamfer, Hausdorff, normal cosine).
    Eval(commands::eval::EvalArgs),
    /// Render flat normal maps of a mesh from the camera rig (what the optimizer sees), with
    /// `cameras.json` describing every view.
    Render(commands::render::RenderArgs),
    /// The watertight, outward-oriented 2-manifold of any soup, decimated to at most N faces.
    Init(commands::init::InitArgs),
    /// Guaranteed QEM of a closed 2-manifold to exactly N faces, without new self-intersections.
    Decimate(commands::decimate::DecimateArgs),
    /// The marching baseline of a signed distance function: its zero set by marching tetrahedra
    /// on a grid of R samples along the longest side, a closed 2-manifold (one JSON line of costs).
    Extract(commands::extract::ExtractArgs),
    /// Write the patches of a range-scan set (a `.conf` or its folder), aligned as
    /// `reconstruct` aligns them, as one mesh to look at.
    Scans(commands::scans::ScansArgs),
    /// Write the messy chair-like example soup that the README runs on.
    ExampleSoup(commands::example::ExampleArgs),
    /// Reconstruct every item of a manifest at one or more budgets, resumably, one child process
    /// per item; `--shard I/K` (or a SLURM array task) runs every K-th item.
    Batch(commands::batch::BatchArgs),
    /// Summarise a batch's output folder in Markdown and JSON: items done, failed and missing,
    /// failures by reason, metric distributions and the worst items.
    BatchReport(commands::batch_report::BatchReportArgs),
}

/// On SIGINT, SIGTERM or SIGHUP: remove the temporary files of the writes in progress (the
/// destinations stay as they were), then exit with 128 + the signal's number, as a shell would
/// report it.
fn clean_up_on_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            roar_io::remove_temporary_files();
            eprintln!("roar: stopped by signal {signal}; unfinished output files removed");
            std::process::exit(128 + signal);
        }
    });
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    clean_up_on_signals();
    let result = match cli.command {
        Command::Reconstruct(args) => commands::reconstruct::run(&args),
        Command::Info(args) => commands::info::run(&args),
        Command::Eval(args) => commands::eval::run(&args),
        Command::Render(args) => commands::render::run(&args),
        Command::Init(args) => commands::init::run(&args),
        Command::Decimate(args) => commands::decimate::run(&args),
        Command::Extract(args) => commands::extract::run(&args),
        Command::Scans(args) => commands::scans::run(&args),
        Command::ExampleSoup(args) => commands::example::run(&args),
        Command::Batch(args) => commands::batch::run(&args),
        Command::BatchReport(args) => commands::batch_report::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("roar: error: {}", roar_cli::checks::one_line(&error));
            ExitCode::FAILURE
        }
    }
}
