//! `roar reconstruct INPUT -o OUTPUT --faces N`: the product. Runs the ROAR pipeline and writes a
//! closed, oriented 2-manifold with exactly N faces and no self-intersections, plus a JSON report
//! (input and output metrics, stage timings, the effective config and the seed).

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use roar_eval::{EvalOptions, Report};
use serde::Serialize;

use crate::checks::check_paths;
use crate::preview::{PreviewInput, PreviewOptions, preview_cameras};
use glam::DVec3;
use roar::Shape;
use roar_mesh::spatial::{Aabb, evaluate_with_gradients};

use roar::shapes::sdf::{DEFAULT_BOUNDS, SdfReport};
use roar::{
    InitKind, Progress as PipelineProgress, ReconstructConfig, Reconstruction, RunStats,
    ScanReport, SdfShape, SoupShape, load_scans,
};

/// Arguments of `roar reconstruct`.
#[derive(Args, Debug, Default)]
pub struct ReconstructArgs {
    /// Any triangle soup (OBJ, PLY, STL or OFF; a PLY range image is its patch), a set of range
    /// scans (a Stanford `.conf` or the folder holding one; `docs/scans.md`), or a signed
    /// distance function: a neural MLP (`.npz`, or an IDR/NeuS `.safetensors` with its `.json`
    /// architecture), an analytic shape (`.sdf.toml`) or a dense grid (`.npy`, bounds from its
    /// `.json` sidecar), negative inside (`docs/sdf.md`).
    pub input: Option<PathBuf>,
    /// Where to write the result (format by extension).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Exact face count of the result (even, at least 4 per piece).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::mesh_files::parse_faces)]
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
    /// Voxels along the longest axis of the watertight init (not with `--init sphere`).
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
    /// Range scans: keep the `.conf` poses (no ICP).
    #[arg(long)]
    pub no_icp: bool,
    /// Write the JSON report to this file.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Also write a PNG picture: input and output from the same four views (the output with its
    /// wireframe) and the loss curve of the run. The input is the soup, a scan set's aligned
    /// patches, or an SDF's zero set traced from those views.
    #[arg(long)]
    pub preview: Option<PathBuf>,
    /// Print the effective configuration as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
    /// Print the JSON report on stdout instead of the summary (`--report` also writes it).
    #[arg(long)]
    pub json: bool,
    /// No progress and no summary (for scripts); errors still go to stderr.
    #[arg(long, short)]
    pub quiet: bool,
    /// Run even when the estimated memory of the budget exceeds what this machine has.
    #[arg(long)]
    pub force: bool,
    /// Box to reconstruct an SDF input in, `xmin,ymin,zmin,xmax,ymax,zmax` (default: a grid's
    /// sidecar bounds, else `-1.1,-1.1,-1.1,1.1,1.1,1.1`); it must hold the zero set. A grid
    /// without a sidecar is placed over it.
    #[arg(long, value_parser = parse_bounds, allow_hyphen_values = true)]
    pub bounds: Option<Aabb>,
}

/// Parses `--bounds`: six finite numbers, each max above its min.
pub(crate) fn parse_bounds(text: &str) -> Result<Aabb, String> {
    let numbers: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|e| format!("{t:?}: {e}")))
        .collect::<Result<_, _>>()?;
    let [x0, y0, z0, x1, y1, z1] = numbers[..] else {
        return Err(format!(
            "six numbers xmin,ymin,zmin,xmax,ymax,zmax, not {}",
            numbers.len()
        ));
    };
    let bounds = Aabb {
        min: DVec3::new(x0, y0, z0),
        max: DVec3::new(x1, y1, z1),
    };
    if !bounds.min.is_finite() || !bounds.max.is_finite() || !bounds.min.cmplt(bounds.max).all() {
        return Err("finite numbers with each max above its min".into());
    }
    Ok(bounds)
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
    /// Seconds for the whole command, up to writing the files.
    pub seconds_total: f64,
    /// Metrics of the input as read (self-intersections skipped: soups can be huge); none for an
    /// SDF input.
    pub input_metrics: Option<Report>,
    /// Metrics of the output, with fidelity against the raw input.
    pub output_metrics: Report,
    /// Pipeline figures and per-stage timings.
    pub run: RunStats,
    /// The effective configuration.
    pub config: ReconstructConfig,
    /// Range scans: each scan's patch and alignment (absent for other inputs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scans: Option<Vec<ScanReport>>,
    /// For an SDF input: its evaluations by stage and how far the output is from its zero set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sdf: Option<SdfRunReport>,
}

/// What a reconstruction of an SDF input adds to the report.
#[derive(Serialize)]
pub struct SdfRunReport {
    /// Evaluations by stage and the tracer's figures.
    #[serde(flatten)]
    pub evaluations: SdfReport,
    /// Mean first-order distance `|f|/|∇f|` of the output's vertices from the zero set, in the
    /// input's units (evaluated after the run, not counted above).
    pub output_distance_mean: f64,
    /// Largest such distance.
    pub output_distance_max: f64,
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
    config.validate().context("config")?;
    if let Some(preview) = &args.preview {
        let png = preview
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        anyhow::ensure!(
            png,
            "{}: --preview writes a PNG picture; name it *.png",
            preview.display()
        );
    }
    let mut inputs = vec![("INPUT", input.as_path())];
    inputs.extend(args.config.as_deref().map(|c| ("--config", c)));
    let mut outputs = vec![("-o", output.as_path())];
    outputs.extend(args.report.as_deref().map(|r| ("--report", r)));
    outputs.extend(args.preview.as_deref().map(|p| ("--preview", p)));
    check_paths(&inputs, &outputs)?;
    roar_io::MeshFormat::for_writing(output)?;
    let started = Instant::now();
    if roar_sdf::is_sdf_path(input) {
        return run_sdf(args, config, input, started);
    }
    let scans = if roar_io::is_scan_set(input) {
        Some(load_scans(input, &config, config.target.scan_icp)?)
    } else {
        None
    };
    let soup = match &scans {
        Some(scans) => scans.union(),
        None => roar_io::read_mesh(input)?,
    };
    check_resources(&config, soup.triangles.len(), args.force)?;

    let mut progress = Progress::new(args.quiet, config.optimize.iterations);
    let mut shape = SoupShape::new(file_name(input), &soup.positions, &soup.triangles, &config)
        .with_scanner_views(scans.as_ref().map_or_else(Vec::new, |s| s.scanner_views()));
    let mut reconstruction = Reconstruction::new(config.clone());
    let result = reconstruction
        .run(&mut shape, &mut |p| progress.report(p))
        .with_context(|| format!("{}: reconstruction failed", input.display()));
    // The prepared target and its renders are not needed for the report.
    drop(shape);
    progress.finish();
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
    let report = ReconstructReport {
        input: input.display().to_string(),
        output: output.display().to_string(),
        seed: config.seed,
        seconds_total: started.elapsed().as_secs_f64(),
        input_metrics: Some(input_metrics),
        output_metrics,
        run: result.stats,
        config,
        scans: scans.map(|s| s.reports),
        sdf: None,
    };
    for scan in report.scans.iter().flatten().filter(|s| !s.overlaps) {
        eprintln!(
            "note: {} overlaps too little of the other scans for ICP; it keeps its .conf pose",
            scan.file
        );
    }
    write_outputs(
        args,
        &report,
        &out_soup,
        PreviewInput::Soup(&soup.positions, &soup.triangles),
    )
}

/// Writes the mesh and the report (all or nothing) and the preview, then prints the summary (or
/// the report with `--json`) on stdout.
fn write_outputs(
    args: &ReconstructArgs,
    report: &ReconstructReport,
    out_soup: &roar_io::TriangleSoup,
    preview_input: PreviewInput<'_>,
) -> anyhow::Result<()> {
    let output = args.output.as_ref().context("-o OUTPUT is required")?;
    for failure in &report.run.optimize.untangle_failures {
        eprintln!(
            "note: {} faces of the loop's state at iteration {} could not be untangled; tried the \
             state with the next lowest loss",
            failure.unresolved_faces, failure.iteration
        );
    }
    let json = serde_json::to_string_pretty(report)?;
    // The mesh and the report are written all or nothing.
    let others: Vec<(&std::path::Path, &[u8])> = args
        .report
        .iter()
        .map(|path| (path.as_path(), json.as_bytes()))
        .collect();
    roar_io::write_mesh_and_files(output, out_soup, &roar_io::WriteOptions::default(), &others)?;
    if let Some(preview) = &args.preview {
        let losses: Vec<f64> = report.run.optimize.history.iter().map(|r| r.loss).collect();
        crate::preview::write_preview(
            preview,
            preview_input,
            (&out_soup.positions, &out_soup.triangles),
            &losses,
            &crate::preview::PreviewOptions::default(),
        )?;
    }
    if args.json {
        println!("{json}");
    } else if !args.quiet {
        print!("{}", summary(args, report));
    }
    Ok(())
}

/// The few lines a person reads after a run: what was written where, its topology, its distance
/// to the input and the time taken.
fn summary(args: &ReconstructArgs, report: &ReconstructReport) -> String {
    let out = &report.output_metrics;
    let topology = &out.topology;
    let genus = topology
        .genus
        .map_or_else(|| "-".to_string(), |g| g.to_string());
    let closed = if topology.watertight {
        "closed"
    } else {
        "NOT closed"
    };
    let crossing = out
        .self_intersections
        .as_ref()
        .map_or_else(|| "-".to_string(), |s| s.faces.to_string());
    let mut text = format!("wrote {} in {:.1} s\n", report.output, report.seconds_total);
    text += &format!(
        "  mesh      {} faces, {closed}, {} piece(s), genus {genus}, {crossing} self-intersecting faces\n",
        topology.faces, topology.components,
    );
    if let Some(fidelity) = &out.fidelity {
        text += &format!(
            "  fidelity  Chamfer/diag to the input {:.3e} (exact closest points {:.3e}), normal cosine {:.4}\n",
            fidelity.chamfer_l2_over_diag,
            fidelity.chamfer_exact_over_diag,
            fidelity.normal_cosine_exact_abs,
        );
    }
    if let Some(sdf) = &report.sdf {
        text += &format!(
            "  field     mean distance of the vertices to the zero set {:.3e}, {} field evaluations\n",
            sdf.output_distance_mean,
            sdf.evaluations.values.values().sum::<u64>()
                + sdf.evaluations.gradients.values().sum::<u64>()
        );
    }
    let dropped = report.run.init.init_pieces_dropped_for_budget;
    if dropped > 0 {
        text += &format!(
            "  pieces    {dropped} piece(s) dropped, the smallest: the budget cannot give every part a closed piece\n"
        );
    }
    let removed = report.run.finish.handles_removed.len();
    if removed > 0 {
        text += &format!(
            "  handles   {removed} removed to reach the budget (--keep-topology fails instead)\n"
        );
    }
    if let Some(path) = &args.report {
        text += &format!("  report    {}\n", path.display());
    }
    if let Some(path) = &args.preview {
        text += &format!("  preview   {}\n", path.display());
    }
    text
}

/// The file name of `path` for messages and reports.
fn file_name(path: &std::path::Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// Reconstructs an SDF input (`.npz`, `.safetensors`, `.sdf.toml`, `.npy`): reads the field (one-line errors, nothing
/// written on failure), runs the pipeline on its [`SdfShape`] inside `--bounds` (or a grid's sidecar bounds), and reports the
/// field's evaluations and how far the output's vertices are from the zero set.
fn run_sdf(
    args: &ReconstructArgs,
    config: ReconstructConfig,
    input: &std::path::Path,
    started: Instant,
) -> anyhow::Result<()> {
    let loaded = roar_sdf::load_sdf_input(input, args.bounds.unwrap_or(DEFAULT_BOUNDS))
        .map_err(|e| anyhow::anyhow!("{}: {e}", input.display()))?;
    let field = loaded.field;
    check_resources(&config, 0, args.force)?;
    let bounds = args.bounds.or(loaded.bounds).unwrap_or(DEFAULT_BOUNDS);
    let mut progress = Progress::new(args.quiet, config.optimize.iterations);
    let mut shape = SdfShape::new(file_name(input), field.clone(), bounds, &config);
    let mut reconstruction = Reconstruction::new(config.clone());
    let result = reconstruction
        .run(&mut shape, &mut |p| progress.report(p))
        .with_context(|| format!("{}: reconstruction failed", input.display()));
    progress.finish();
    let result = result?;
    // Traced before the report, so the report counts the preview's evaluations.
    let preview_views = args
        .preview
        .as_ref()
        .map(|_| shape.preview_views(&preview_cameras(PreviewOptions::default().tile)))
        .unwrap_or_default();
    let evaluations = shape.report();
    let (values, gradients) = evaluate_with_gradients(field.as_ref(), &result.positions);
    let distances: Vec<f64> = values
        .iter()
        .zip(&gradients)
        .map(|(f, g)| f.abs() / g.length())
        .collect();
    let out_soup = roar_io::TriangleSoup::new(result.positions, result.triangles);
    let output_metrics = roar_eval::evaluate(
        &out_soup.positions,
        &out_soup.triangles,
        None,
        &EvalOptions::default(),
    )?;
    let report = ReconstructReport {
        input: input.display().to_string(),
        output: args
            .output
            .as_ref()
            .map(|o| o.display().to_string())
            .unwrap_or_default(),
        seed: config.seed,
        seconds_total: started.elapsed().as_secs_f64(),
        input_metrics: None,
        output_metrics,
        run: result.stats,
        config,
        scans: None,
        sdf: Some(SdfRunReport {
            evaluations,
            output_distance_mean: distances.iter().sum::<f64>() / distances.len().max(1) as f64,
            output_distance_max: distances.iter().copied().fold(0.0, f64::max),
        }),
    };
    let preview_input = PreviewInput::Views {
        normalization: shape.normalization(),
        views: &preview_views,
    };
    write_outputs(args, &report, &out_soup, preview_input)
}

/// `defaults` overridden by the keys of the TOML file at `path`, if any; a parse error or an
/// unknown key is one line naming the file.
pub fn read_config(
    path: Option<&std::path::Path>,
    defaults: ReconstructConfig,
) -> anyhow::Result<ReconstructConfig> {
    let Some(path) = path else {
        return Ok(defaults);
    };
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    ReconstructConfig::from_toml(&text, &defaults).with_context(|| path.display().to_string())
}

/// Defaults, then the TOML file, then the flags.
/// The defaults are the SDF schedule's ([`ReconstructConfig::sdf_defaults`]) for an SDF input.
pub fn effective_config(args: &ReconstructArgs) -> anyhow::Result<ReconstructConfig> {
    let defaults = match args.input.as_deref() {
        Some(input) if roar_sdf::is_sdf_path(input) => ReconstructConfig::sdf_defaults(),
        Some(input) if roar_io::is_scan_set(input) => ReconstructConfig::scan_defaults(),
        _ => ReconstructConfig::default(),
    };
    let mut config = read_config(args.config.as_deref(), defaults)?;
    if let Some(faces) = args.faces {
        config.faces = faces;
    }
    if let Some(init) = &args.init {
        config.init.kind = if init == "sphere" {
            InitKind::Sphere
        } else {
            InitKind::Watertight
        };
    }
    if args.no_icp {
        config.target.scan_icp = false;
    }
    if let Some(iterations) = args.iterations {
        config.optimize.iterations = iterations;
    }
    if let Some(resolution) = args.resolution {
        if config.init.kind == InitKind::Sphere {
            anyhow::bail!(
                "--resolution sets the watertight init's voxels; it has no effect with --init sphere"
            );
        }
        config.init.init_resolution = resolution;
    }
    if let Some(seed) = args.seed {
        config.seed = seed;
    }
    if args.best_effort {
        config.finish.best_effort = true;
    }
    if args.keep_topology {
        config.finish.keep_topology = true;
    }
    Ok(config)
}

/// Progress of a run on stderr: a bar on a terminal, otherwise plain lines now and then.
struct Progress {
    bar: Option<ProgressBar>,
    lines: ProgressLines,
}

impl Progress {
    fn new(quiet: bool, iterations: usize) -> Self {
        let bar = progress_bar(quiet, iterations);
        let lines = ProgressLines::new(quiet || bar.is_some());
        Self { bar, lines }
    }

    fn report(&mut self, p: &PipelineProgress) {
        self.lines.report(p);
        if let Some(bar) = &self.bar {
            bar.set_position(p.iteration as u64);
            bar.set_message(if p.loss.is_finite() {
                format!("{:<10} loss {:.5} faces {}", p.stage, p.loss, p.faces)
            } else {
                format!("{:<10} faces {}", p.stage, p.faces)
            });
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// A progress bar when stderr is a terminal and not `--quiet`.
fn progress_bar(quiet: bool, iterations: usize) -> Option<ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
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

/// Plain progress lines on stderr, at most one every [`ProgressLines::EVERY`], for when there is
/// no progress bar (stderr is a file or a pipe): a long run is never silent.
struct ProgressLines {
    started: Instant,
    last: Option<Instant>,
    off: bool,
}

impl ProgressLines {
    const EVERY: Duration = Duration::from_secs(10);

    fn new(off: bool) -> Self {
        Self {
            started: Instant::now(),
            last: None,
            off,
        }
    }

    fn report(&mut self, p: &PipelineProgress) {
        let now = Instant::now();
        let due = self.last.is_none_or(|last| now - last >= Self::EVERY);
        if self.off || !due {
            return;
        }
        self.last = Some(now);
        eprintln!(
            "roar: {:6.1} s  {:<10} iteration {}/{}  faces {}",
            (now - self.started).as_secs_f64(),
            p.stage,
            p.iteration,
            p.iterations,
            p.faces
        );
    }
}

/// Refuses, before the run, a budget whose estimated peak memory
/// ([`roar::budget::estimated_peak_bytes`]) exceeds the memory this machine has available
/// (`MemAvailable` of `/proc/meminfo`), unless `force`.
fn check_resources(
    config: &ReconstructConfig,
    input_faces: usize,
    force: bool,
) -> anyhow::Result<()> {
    let needed = roar::budget::estimated_peak_bytes(&roar::budget::RunSizes {
        working_faces: config.working_budget(),
        input_faces,
        render_pixels: (config.target.views_per_axis * config.target.views_per_axis) as u64
            * u64::from(config.target.render_resolution).pow(2),
        cloud_samples: config.target.point_cloud_samples,
    });
    let Some(available) = roar::budget::available_memory_bytes() else {
        return Ok(());
    };
    if needed > available && !force {
        anyhow::bail!(
            "--faces {} needs about {:.1} GiB (working budget {} faces), but {:.1} GiB are \
             available; use a smaller budget, or --force to try anyway",
            config.faces,
            needed as f64 / GIB,
            config.working_budget(),
            available as f64 / GIB
        );
    }
    Ok(())
}

const GIB: f64 = (1u64 << 30) as f64;
