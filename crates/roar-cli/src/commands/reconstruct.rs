//! `roar reconstruct INPUT -o OUTPUT --faces N`: the product. Runs the ROAR pipeline and writes a
//! closed, oriented 2-manifold with exactly N faces and no self-intersections, plus a JSON report
//! (input and output metrics, stage timings, the effective config and the seed).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use roar_eval::{EvalOptions, Report};
use serde::Serialize;

use crate::pipeline::{InitKind, Progress, ReconstructConfig, Reconstruction, RunStats};

/// Arguments of `roar reconstruct`.
#[derive(Args, Debug)]
pub struct ReconstructArgs {
    /// Any triangle soup (OBJ, PLY, STL or OFF).
    pub input: Option<PathBuf>,
    /// Where to write the result (format by extension).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Exact face count of the result (even).
    #[arg(long)]
    pub faces: Option<usize>,
    /// TOML file overriding any configuration key (see `--print-config`).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Initial mesh: `watertight` (default) or `sphere`.
    #[arg(long, value_parser = ["watertight", "sphere"])]
    pub init: Option<String>,
    /// Move Vertices iterations.
    #[arg(long)]
    pub iterations: Option<usize>,
    /// Voxels along the longest axis of the watertight init.
    #[arg(long)]
    pub resolution: Option<usize>,
    /// Seed of every random choice.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Write the closest mesh if the budget cannot be met, instead of failing.
    #[arg(long)]
    pub best_effort: bool,
    /// Keep the genus: fail when the budget is too small for it instead of removing handles.
    #[arg(long)]
    pub keep_topology: bool,
    /// Also write the JSON report to this file.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Print the effective configuration as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
    /// No progress bar and no report on stdout (for scripts).
    #[arg(long, short)]
    pub quiet: bool,
}

/// The JSON report of one reconstruction.
#[derive(Serialize)]
pub struct ReconstructReport {
    /// The input file.
    pub input: String,
    /// The output file.
    pub output: String,
    /// Seed of the run.
    pub seed: u64,
    /// Seconds for the whole command.
    pub seconds_total: f64,
    /// Metrics of the input as read (self-intersections skipped: soups can be huge).
    pub input_metrics: Report,
    /// Metrics of the output, with fidelity against the raw input.
    pub output_metrics: Report,
    /// Pipeline figures and per-stage timings.
    pub run: RunStats,
    /// The effective configuration.
    pub config: ReconstructConfig,
}

/// Runs `roar reconstruct`.
pub fn run(args: &ReconstructArgs) -> anyhow::Result<()> {
    let config = effective_config(args)?;
    if args.print_config {
        print!("{}", toml::to_string(&config)?);
        return Ok(());
    }
    let input = args
        .input
        .as_ref()
        .context("an INPUT file is required (or --print-config)")?;
    let output = args.output.as_ref().context("-o OUTPUT is required")?;
    config.validate().map_err(|e| anyhow::anyhow!(e))?;
    roar_io::MeshFormat::from_path(output)?;
    let started = Instant::now();
    let soup = roar_io::read_mesh(input)?;

    let bar = progress_bar(args.quiet, config.iterations);
    let mut on_progress = |p: &Progress| {
        if let Some(bar) = &bar {
            bar.set_position(p.iteration as u64);
            bar.set_message(if p.loss.is_finite() {
                format!("{:<10} loss {:.5} faces {}", p.stage, p.loss, p.faces)
            } else {
                format!("{:<10} faces {}", p.stage, p.faces)
            });
        }
    };
    let mut reconstruction = Reconstruction::new(config.clone());
    let result = reconstruction
        .run(&soup.positions, &soup.triangles, &mut on_progress)
        .with_context(|| format!("{}: reconstruction failed", input.display()));
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let result = result?;

    let out_soup = roar_io::TriangleSoup::new(result.positions, result.triangles);
    // Soups can be large and their self-intersections are not what the report is about.
    let eval_input = EvalOptions {
        self_intersections: None,
        ..EvalOptions::default()
    };
    let input_metrics = roar_eval::evaluate(&soup.positions, &soup.triangles, None, &eval_input)?;
    let output_metrics = roar_eval::evaluate(
        &out_soup.positions,
        &out_soup.triangles,
        Some((&soup.positions, &soup.triangles)),
        &EvalOptions::default(),
    )?;
    roar_io::write_mesh(output, &out_soup)?;
    let report = ReconstructReport {
        input: input.display().to_string(),
        output: output.display().to_string(),
        seed: config.seed,
        seconds_total: started.elapsed().as_secs_f64(),
        input_metrics,
        output_metrics,
        run: result.stats,
        config,
    };
    for failure in &report.run.untangle_failures {
        eprintln!(
            "note: {} faces of the loop's state at iteration {} could not be untangled; tried the \
             state with the next lowest loss",
            failure.unresolved_faces, failure.iteration
        );
    }
    let json = serde_json::to_string_pretty(&report)?;
    if let Some(path) = &args.report {
        roar_io::atomic_write(path, |w| w.write_all(json.as_bytes()))?;
    }
    if !args.quiet {
        println!("{json}");
    }
    eprintln!(
        "wrote {} ({} faces) in {:.1} s",
        output.display(),
        out_soup.triangles.len(),
        report.seconds_total
    );
    Ok(())
}

/// Defaults, then the TOML file, then the flags.
fn effective_config(args: &ReconstructArgs) -> anyhow::Result<ReconstructConfig> {
    let mut config = match &args.config {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            toml::from_str(&text).map_err(|e| {
                anyhow::anyhow!("{}: {}", path.display(), e.to_string().replace('\n', " "))
            })?
        }
        None => ReconstructConfig::default(),
    };
    if let Some(faces) = args.faces {
        config.faces = faces;
    }
    if let Some(init) = &args.init {
        config.init = if init == "sphere" {
            InitKind::Sphere
        } else {
            InitKind::Watertight
        };
    }
    if let Some(iterations) = args.iterations {
        config.iterations = iterations;
    }
    if let Some(resolution) = args.resolution {
        config.init_resolution = resolution;
    }
    if let Some(seed) = args.seed {
        config.seed = seed;
    }
    if args.best_effort {
        config.best_effort = true;
    }
    if args.keep_topology {
        config.keep_topology = true;
    }
    Ok(config)
}

fn progress_bar(quiet: bool, iterations: usize) -> Option<ProgressBar> {
    if quiet {
        return None;
    }
    let bar = ProgressBar::new(iterations as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:30}] {pos}/{len} it, eta {eta} {msg}",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    Some(bar)
}
