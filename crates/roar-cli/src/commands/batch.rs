//! `roar batch MANIFEST -o OUTDIR --faces N[,N2,…]`: every item of a manifest reconstructed at
//! every budget, each in a child `roar reconstruct` process, skipping what an earlier run already
//! finished with the same input, configuration and build (see `crate::batch` for the files).
//!
//! Exit status 0 only when every item and budget of this shard succeeded; the last line on
//! stderr is the summary either way.

use std::ffi::OsString;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

use crate::batch::child::{ChildOptions, ChildOutcome, run_child};
use crate::batch::hash::{hash_bytes, hash_path};
use crate::batch::layout::{
    FailureRecord, ItemFiles, ItemRecord, Plan, PlanItem, failures_log, plan_path,
    remove_if_present,
};
use crate::batch::manifest::{Item, parse_budgets, parse_seconds, read_manifest};
use crate::batch::shard::Shard;
use crate::commands::reconstruct::{ReconstructArgs, effective_config};

/// Arguments of `roar batch`.
#[derive(Args, Debug)]
pub struct BatchArgs {
    /// The manifest: one input path a line, or CSV/TSV with a header naming `path` and
    /// optionally `id`, `faces`, `iterations`, `seed`, `timeout`; other columns are labels.
    pub manifest: PathBuf,
    /// Output folder: `OUTDIR/<id>/<budget>.<format>` and `<budget>.json` per item.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Face budgets, comma separated (an item's `faces` column replaces them).
    #[arg(long)]
    pub faces: String,
    /// Mesh format of the outputs: obj, ply, stl or off.
    #[arg(long, default_value = "obj")]
    pub format: String,
    /// TOML file overriding any configuration key (as for `roar reconstruct`).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Initial mesh: `watertight` (default) or `sphere`.
    #[arg(long, value_parser = ["watertight", "sphere"])]
    pub init: Option<String>,
    /// Move Vertices iterations (an item's `iterations` column replaces it).
    #[arg(long)]
    pub iterations: Option<usize>,
    /// Voxels along the longest axis of the watertight init.
    #[arg(long)]
    pub resolution: Option<usize>,
    /// Seed of every random choice (an item's `seed` column replaces it).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Write the closest mesh if a budget cannot be met, instead of failing the item.
    #[arg(long)]
    pub best_effort: bool,
    /// Run shard I of K (every K-th item from the I-th, 0-based). Default: from
    /// SLURM_ARRAY_TASK_ID/_COUNT/_MIN/_STEP inside an array job, else the whole manifest.
    #[arg(long)]
    pub shard: Option<String>,
    /// Items run at once in this task; the cores are split between them.
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
    /// Seconds one item and budget may take before it is killed and recorded as failed.
    #[arg(long, value_parser = parse_seconds)]
    pub timeout: Option<f64>,
    /// Resident memory one item may use before it is killed (bytes, or with K, M, G suffix).
    #[arg(long, value_parser = parse_memory)]
    pub max_memory: Option<u64>,
    /// Only the summary line on stderr.
    #[arg(long, short)]
    pub quiet: bool,
}

/// One item at one budget.
struct Task<'a> {
    item: &'a Item,
    budget: usize,
}

/// How one task ended.
enum TaskResult {
    Skipped,
    Done { seconds: f64 },
    Failed(FailureRecord),
}

/// What every task shares.
struct Shared<'a> {
    args: &'a BatchArgs,
    outdir: &'a Path,
    format: String,
    exe: PathBuf,
    build: String,
    threads_per_item: usize,
}

/// Runs `roar batch`.
pub fn run(args: &BatchArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    if args.jobs == 0 {
        bail!("--jobs must be at least 1");
    }
    let budgets = parse_budgets(&args.faces).context("--faces")?;
    let format = args.format.to_ascii_lowercase();
    roar_io::MeshFormat::from_path(Path::new(&format!("mesh.{format}")))
        .with_context(|| format!("--format {}", args.format))?;
    let shard = match &args.shard {
        Some(text) => Shard::parse(text)?,
        None => Shard::from_slurm(|name| std::env::var(name).ok())?.unwrap_or(Shard::ALL),
    };
    let items = read_manifest(&args.manifest)?;
    // A broken --config fails the whole batch up front rather than every item.
    effective_config(&reconstruct_args(args, None, None))?;

    let outdir = args.output.as_path();
    std::fs::create_dir_all(outdir)
        .with_context(|| format!("cannot create {}", outdir.display()))?;
    if shard.index == 0 {
        write_plan(args, &items, &budgets, &format)?;
    }
    let exe = std::env::current_exe().context("cannot find the roar executable")?;
    let build = hash_path(&exe).context("cannot hash the roar executable")?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let context = Shared {
        args,
        outdir,
        format: format.clone(),
        exe,
        build,
        threads_per_item: (cores / args.jobs).max(1),
    };
    let tasks: Vec<Task> = items
        .iter()
        .enumerate()
        .filter(|(position, _)| shard.contains(*position))
        .flat_map(|(_, item)| {
            let item_budgets = item.faces.clone().unwrap_or_else(|| budgets.clone());
            item_budgets
                .into_iter()
                .map(move |budget| Task { item, budget })
        })
        .collect();
    let log_path = failures_log(outdir, shard.index, shard.count);
    let mut failures_log_file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&log_path)
        .with_context(|| format!("cannot open {}", log_path.display()))?;

    let progress = Progress::new(tasks.len(), args.quiet, args.jobs);
    let (mut done, mut skipped, mut failed) = (0usize, 0usize, 0usize);
    let next = AtomicUsize::new(0);
    std::thread::scope(|scope| -> anyhow::Result<()> {
        let (sender, receiver) = mpsc::channel();
        for _ in 0..args.jobs.min(tasks.len()) {
            let sender = sender.clone();
            let (tasks, next, context) = (&tasks, &next, &context);
            scope.spawn(move || {
                loop {
                    let index = next.fetch_add(1, Ordering::Relaxed);
                    let Some(task) = tasks.get(index) else { break };
                    let result = run_task(context, task);
                    if sender.send((index, result)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(sender);
        for (index, result) in receiver {
            let task = &tasks[index];
            match &result {
                TaskResult::Skipped => skipped += 1,
                TaskResult::Done { .. } => done += 1,
                TaskResult::Failed(failure) => {
                    failed += 1;
                    let line = serde_json::to_string(failure)?;
                    writeln!(failures_log_file, "{line}")
                        .and_then(|()| failures_log_file.flush())
                        .with_context(|| format!("cannot write {}", log_path.display()))?;
                }
            }
            progress.finished(task, &result);
        }
        Ok(())
    })?;
    progress.clear();

    let summary = format!(
        "{} of {} item budgets done ({done} run, {skipped} already done), {failed} failed, shard \
         {}/{} of {} items, {:.1} s",
        done + skipped,
        tasks.len(),
        shard.index,
        shard.count,
        items.len(),
        started.elapsed().as_secs_f64()
    );
    if failed > 0 {
        bail!("batch: {summary}; failures in {}", log_path.display());
    }
    eprintln!("roar batch: {summary}");
    Ok(())
}

/// The `reconstruct` arguments of an item (or of the batch alone), for the configuration hash.
/// The item's input is among them: it picks the defaults (an SDF input's schedule, a scan
/// set's) that the child starts from.
fn reconstruct_args(
    args: &BatchArgs,
    item: Option<&Item>,
    budget: Option<usize>,
) -> ReconstructArgs {
    ReconstructArgs {
        input: item.map(|i| i.input.clone()),
        output: None,
        faces: budget,
        config: args.config.clone(),
        init: args.init.clone(),
        iterations: item.and_then(|i| i.iterations).or(args.iterations),
        resolution: args.resolution,
        seed: item.and_then(|i| i.seed).or(args.seed),
        best_effort: args.best_effort,
        no_icp: false,
        report: None,
        print_config: false,
        json: false,
        quiet: true,
        force: false,
        preview: None,
        keep_topology: false,
        bounds: None,
    }
}

/// The command line of the child `roar reconstruct` for one task.
fn child_args(args: &BatchArgs, task: &Task, files: &ItemFiles) -> Vec<OsString> {
    let r = reconstruct_args(args, Some(task.item), Some(task.budget));
    let mut out: Vec<OsString> = vec![
        "reconstruct".into(),
        task.item.input.clone().into(),
        "-o".into(),
        files.partial_mesh.clone().into(),
        "--faces".into(),
        task.budget.to_string().into(),
        "--report".into(),
        files.partial_report.clone().into(),
        "--quiet".into(),
    ];
    let mut flag = |name: &str, value: Option<String>| {
        if let Some(value) = value {
            out.push(name.into());
            out.push(value.into());
        }
    };
    flag("--config", r.config.map(|p| p.display().to_string()));
    flag("--init", r.init);
    flag("--iterations", r.iterations.map(|n| n.to_string()));
    flag("--resolution", r.resolution.map(|n| n.to_string()));
    flag("--seed", r.seed.map(|n| n.to_string()));
    if r.best_effort {
        out.push("--best-effort".into());
    }
    out
}

/// Runs one task: skipped when done with the same fingerprints, else a fresh attempt.
fn run_task(context: &Shared, task: &Task) -> TaskResult {
    let started = Instant::now();
    let files = ItemFiles::new(context.outdir, &task.item.id, task.budget, &context.format);
    let fail = |reason: String| {
        let failure = FailureRecord {
            id: task.item.id.clone(),
            budget: task.budget,
            reason,
            seconds: started.elapsed().as_secs_f64(),
        };
        // The failures log is the primary record; this file only feeds `batch-report`.
        let json = serde_json::to_string_pretty(&failure).unwrap_or_default();
        let _ = roar_io::atomic_write(&files.failure, |w| w.write_all(json.as_bytes()));
        TaskResult::Failed(failure)
    };
    let config = match effective_config(&reconstruct_args(
        context.args,
        Some(task.item),
        Some(task.budget),
    ))
    .and_then(|c| Ok(toml::to_string(&c)?))
    {
        Ok(text) => hash_bytes(text.as_bytes()),
        Err(e) => return fail(format!("{e:#}")),
    };
    let input_hash = match hash_path(&task.item.input) {
        Ok(h) => h,
        Err(e) => {
            let _ = std::fs::create_dir_all(&files.folder);
            return fail(format!("{e:#}"));
        }
    };
    if files.is_done(&input_hash, &config, &context.build) {
        return TaskResult::Skipped;
    }
    if let Err(e) = std::fs::create_dir_all(&files.folder).and_then(|()| files.clear()) {
        return fail(format!("cannot prepare {}: {e}", files.folder.display()));
    }
    let options = ChildOptions {
        program: context.exe.clone(),
        args: child_args(context.args, task, &files),
        env: vec![(
            "RAYON_NUM_THREADS".to_string(),
            context.threads_per_item.to_string(),
        )],
        timeout: task
            .item
            .timeout
            .or(context.args.timeout)
            .map(Duration::from_secs_f64),
        max_memory: context.args.max_memory,
        log: files.log.clone(),
    };
    let seconds = match run_child(&options) {
        ChildOutcome::Success { seconds } => seconds,
        ChildOutcome::Failure { reason, .. } => {
            for path in files.leftovers() {
                let _ = remove_if_present(&path);
            }
            return fail(reason);
        }
    };
    match finish(&files, task, input_hash, config, &context.build, seconds) {
        Ok(()) => TaskResult::Done { seconds },
        Err(e) => fail(format!("{e:#}")),
    }
}

/// Moves the child's mesh into place, then writes the record that marks the task done.
fn finish(
    files: &ItemFiles,
    task: &Task,
    input_hash: String,
    config_hash: String,
    build: &str,
    seconds: f64,
) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(&files.partial_report).with_context(|| {
        format!(
            "the child wrote no report {}",
            files.partial_report.display()
        )
    })?;
    let reconstruct: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not JSON", files.partial_report.display()))?;
    std::fs::rename(&files.partial_mesh, &files.mesh)
        .with_context(|| format!("cannot move {}", files.partial_mesh.display()))?;
    let record = ItemRecord {
        id: task.item.id.clone(),
        budget: task.budget,
        input: task.item.input.display().to_string(),
        input_hash,
        config_hash,
        build: build.to_string(),
        seconds,
        labels: task.item.labels.clone(),
        reconstruct,
    };
    let json = serde_json::to_string_pretty(&record)?;
    roar_io::atomic_write(&files.record, |w| w.write_all(json.as_bytes()))?;
    remove_if_present(&files.partial_report)?;
    remove_if_present(&files.failure)?;
    Ok(())
}

fn write_plan(
    args: &BatchArgs,
    items: &[Item],
    budgets: &[usize],
    format: &str,
) -> anyhow::Result<()> {
    let plan = Plan {
        manifest: args.manifest.display().to_string(),
        format: format.to_string(),
        items: items
            .iter()
            .map(|item| PlanItem {
                id: item.id.clone(),
                input: item.input.display().to_string(),
                budgets: item.faces.clone().unwrap_or_else(|| budgets.to_vec()),
                labels: item.labels.clone(),
            })
            .collect(),
    };
    let json = serde_json::to_string_pretty(&plan)?;
    roar_io::atomic_write(&plan_path(&args.output), |w| w.write_all(json.as_bytes()))?;
    Ok(())
}

/// Parses a memory size: bytes, or a number with a K, M or G suffix (powers of 1024).
fn parse_memory(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let (number, unit) = match t.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => (&t[..i], t[i..].to_ascii_uppercase()),
        None => (t, String::new()),
    };
    let scale: u64 = match unit.trim_end_matches("IB").trim_end_matches('B') {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => return Err(format!("{text:?} is not a memory size (e.g. 4G, 512M)")),
    };
    match number.trim().parse::<f64>() {
        Ok(n) if n.is_finite() && n > 0.0 => Ok((n * scale as f64) as u64),
        _ => Err(format!("{text:?} is not a memory size (e.g. 4G, 512M)")),
    }
}

/// A progress bar with ETA on a terminal, one plain line per finished task otherwise.
struct Progress {
    bar: Option<ProgressBar>,
    plain: bool,
    total: usize,
    jobs: usize,
    started: Instant,
    state: std::sync::Mutex<(usize, f64, usize)>,
}

impl Progress {
    fn new(total: usize, quiet: bool, jobs: usize) -> Self {
        let terminal = std::io::stderr().is_terminal();
        let bar = (!quiet && terminal).then(|| {
            let bar = ProgressBar::new(total as u64);
            bar.set_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:30}] {pos}/{len} items, eta {eta} {msg}",
                )
                .expect("static template")
                .progress_chars("=> "),
            );
            bar
        });
        Self {
            bar,
            plain: !quiet && !terminal,
            total,
            jobs,
            started: Instant::now(),
            state: std::sync::Mutex::new((0, 0.0, 0)),
        }
    }

    fn finished(&self, task: &Task, result: &TaskResult) {
        let Ok(mut state) = self.state.lock() else {
            return;
        };
        let (finished, run_seconds, run_count) = &mut *state;
        *finished += 1;
        let what = match result {
            TaskResult::Skipped => "already done".to_string(),
            TaskResult::Done { seconds } => {
                *run_seconds += seconds;
                *run_count += 1;
                format!("done in {seconds:.1} s")
            }
            TaskResult::Failed(f) => {
                *run_seconds += f.seconds;
                *run_count += 1;
                format!("FAILED: {}", f.reason)
            }
        };
        let message = format!("{} {} {what}", task.item.id, task.budget);
        if let Some(bar) = &self.bar {
            bar.set_position(*finished as u64);
            bar.set_message(message);
        } else if self.plain {
            // The ETA assumes the remaining tasks take as long as the ones run so far.
            let remaining = (self.total - *finished) as f64;
            let eta = if *run_count > 0 {
                remaining * *run_seconds / *run_count as f64 / self.jobs as f64
            } else {
                0.0
            };
            eprintln!(
                "roar batch: [{finished}/{}] {message}; {:.0} s elapsed, eta {eta:.0} s",
                self.total,
                self.started.elapsed().as_secs_f64()
            );
        }
    }

    fn clear(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{BatchArgs, effective_config, parse_memory, reconstruct_args};
    use crate::batch::manifest::Item;
    use clap::Parser;
    use roar::ReconstructConfig;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: BatchArgs,
    }

    #[test]
    fn an_item_is_hashed_with_the_defaults_of_its_input_kind() {
        let cli = Cli::parse_from(["batch", "manifest.csv", "-o", "out", "--faces", "200"]);
        let config_of = |input: &str| {
            let item = Item {
                id: "x".into(),
                input: input.into(),
                faces: None,
                iterations: None,
                seed: None,
                timeout: None,
                labels: Default::default(),
                line: 2,
            };
            effective_config(&reconstruct_args(&cli.args, Some(&item), Some(200))).unwrap()
        };
        // What the child `roar reconstruct ITEM --faces 200` starts from.
        let faces = |c: ReconstructConfig| ReconstructConfig { faces: 200, ..c };
        assert_eq!(
            config_of("net.npz"),
            faces(ReconstructConfig::sdf_defaults())
        );
        assert_eq!(
            config_of("grid.npy"),
            faces(ReconstructConfig::sdf_defaults())
        );
        assert_eq!(config_of("chair.obj"), faces(ReconstructConfig::default()));
        assert_ne!(config_of("net.npz"), config_of("chair.obj"));
    }

    #[test]
    fn memory_sizes_parse() {
        assert_eq!(parse_memory("1024"), Ok(1024));
        assert_eq!(parse_memory("4G"), Ok(4 << 30));
        assert_eq!(parse_memory("512MiB"), Ok(512 << 20));
        assert_eq!(parse_memory("1.5k"), Ok(1536));
        for bad in ["", "G", "-1G", "4T", "nanM"] {
            assert!(parse_memory(bad).is_err(), "{bad}");
        }
    }
}
