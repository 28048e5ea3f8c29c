//! `roar scans SET -o patches.ply`: the patches of a range-scan set (a `.conf` or its folder),
//! aligned as `roar reconstruct` aligns them, written as one mesh so a user can look at them;
//! each scan's patch figures and ICP residuals go to stdout as JSON.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use crate::checks::check_paths;
use roar::{ReconstructConfig, load_scans};

/// Arguments of `roar scans`.
#[derive(Args, Debug)]
pub struct ScansArgs {
    /// A Stanford `.conf` scan set, or the folder holding one.
    pub input: PathBuf,
    /// Where to write the aligned patches (format by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Keep the `.conf` poses (no ICP).
    #[arg(long)]
    pub no_icp: bool,
    /// TOML file of `roar reconstruct`'s configuration (its `scan_*` keys set the patch
    /// filters).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Print each scan's patch and alignment as JSON on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No summary on stdout.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `roar scans`.
pub fn run(args: &ScansArgs) -> anyhow::Result<()> {
    let mut inputs = vec![("INPUT", args.input.as_path())];
    inputs.extend(args.config.as_deref().map(|c| ("--config", c)));
    check_paths(&inputs, &[("-o", &args.output)])?;
    roar_io::MeshFormat::for_writing(&args.output)?;
    let config = crate::commands::reconstruct::read_config(
        args.config.as_deref(),
        ReconstructConfig::scan_defaults(),
    )?;
    config.validate().context("config")?;
    anyhow::ensure!(
        roar_io::is_scan_set(&args.input),
        "{}: not a scan set (name a .conf file or the folder holding one)",
        args.input.display()
    );
    let scans = load_scans(&args.input, &config, config.target.scan_icp && !args.no_icp)?;
    let union = scans.union();
    roar_io::write_mesh(&args.output, &union)?;
    for scan in scans.reports.iter().filter(|s| !s.overlaps) {
        eprintln!(
            "note: {} overlaps too little of the other scans for ICP; it keeps its .conf pose",
            scan.file
        );
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&scans.reports)?);
    } else if !args.quiet {
        println!(
            "wrote {} ({} scans, {} triangles)",
            args.output.display(),
            scans.patches.len(),
            union.triangles.len()
        );
    }
    Ok(())
}
