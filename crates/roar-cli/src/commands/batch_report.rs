//! `roar batch-report OUTDIR`: the summary of a batch's output folder, as Markdown on stdout and
//! in `OUTDIR/report.md`, and as JSON in `OUTDIR/report.json`: items done, failed and missing,
//! failures grouped by reason, the median, p10 and p90 of each metric per budget, and the worst
//! items by Chamfer distance.
//!
//! It reads only files: `OUTDIR/manifest.json` (the plan a batch writes) and each item's
//! `<budget>.json` or `<budget>.failure.json`, so it can run while shards are still going.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use serde::Serialize;

use crate::batch::layout::{FailureRecord, ItemFiles, Plan, plan_path};

/// Arguments of `roar batch-report`.
#[derive(Args, Debug)]
pub struct BatchReportArgs {
    /// The output folder of `roar batch`.
    pub outdir: PathBuf,
    /// How many of the worst items to list.
    #[arg(long, default_value_t = 10)]
    pub worst: usize,
}

/// The JSON summary.
#[derive(Debug, Serialize)]
pub struct BatchSummary {
    /// Items in the manifest.
    pub items: usize,
    /// Item budgets in the manifest (items × their budgets).
    pub item_budgets: usize,
    /// Item budgets with a finished record.
    pub done: usize,
    /// Item budgets whose last attempt failed.
    pub failed: usize,
    /// Item budgets not attempted yet (or interrupted).
    pub missing: usize,
    /// Failures grouped by reason (the input's path replaced by `INPUT`), most frequent first.
    pub failures_by_reason: Vec<ReasonCount>,
    /// Distributions per budget.
    pub budgets: Vec<BudgetSummary>,
    /// The worst finished item budgets by Chamfer/diag, worst first.
    pub worst: Vec<WorstItem>,
    /// Every failure.
    pub failures: Vec<FailureRecord>,
    /// Every missing item budget as `id/budget`.
    pub missing_items: Vec<String>,
}

/// How many failures share one reason.
#[derive(Debug, Serialize)]
pub struct ReasonCount {
    /// The reason.
    pub reason: String,
    /// How many item budgets failed with it.
    pub count: usize,
}

/// The distributions of one budget's finished items.
#[derive(Debug, Serialize)]
pub struct BudgetSummary {
    /// The face budget.
    pub budget: usize,
    /// Finished items at this budget.
    pub done: usize,
    /// Chamfer L2 over the reference's bounding-box diagonal.
    pub chamfer_over_diag: Option<Quantiles>,
    /// Mean normal cosine to the input.
    pub normal_cosine: Option<Quantiles>,
    /// Median triangle aspect ratio of each output.
    pub aspect_ratio_median: Option<Quantiles>,
    /// Genus of each output.
    pub genus: Option<Quantiles>,
    /// Seconds of each item's child process.
    pub seconds: Option<Quantiles>,
}

/// Median, 10th and 90th percentile (nearest rank) of a sample.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Quantiles {
    /// 10th percentile.
    pub p10: f64,
    /// Median.
    pub median: f64,
    /// 90th percentile.
    pub p90: f64,
    /// Sample size.
    pub n: usize,
}

/// One of the worst items.
#[derive(Debug, Serialize)]
pub struct WorstItem {
    /// Its id.
    pub id: String,
    /// Its budget.
    pub budget: usize,
    /// Chamfer L2 over the reference diagonal.
    pub chamfer_over_diag: f64,
    /// Normal cosine, if measured.
    pub normal_cosine: Option<f64>,
}

/// Nearest-rank quantiles of the finite values; `None` when there are none.
pub fn quantiles(values: &[f64]) -> Option<Quantiles> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let rank = |q: f64| v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    Some(Quantiles {
        p10: rank(0.1),
        median: rank(0.5),
        p90: rank(0.9),
        n: v.len(),
    })
}

/// Reads an output folder into its summary.
pub fn summarize(outdir: &std::path::Path, worst_count: usize) -> anyhow::Result<BatchSummary> {
    let plan_file = plan_path(outdir);
    let text = std::fs::read_to_string(&plan_file).with_context(|| {
        format!(
            "cannot read {} (is {} the output of `roar batch`?)",
            plan_file.display(),
            outdir.display()
        )
    })?;
    let plan: Plan =
        serde_json::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", plan_file.display()))?;
    let (mut done, mut item_budgets) = (0, 0);
    let mut failures = Vec::new();
    let mut missing_items = Vec::new();
    let mut reasons: BTreeMap<String, usize> = BTreeMap::new();
    let mut per_budget: BTreeMap<usize, Vec<[Option<f64>; 5]>> = BTreeMap::new();
    let mut worst = Vec::new();
    for item in &plan.items {
        for &budget in &item.budgets {
            item_budgets += 1;
            let files = ItemFiles::new(outdir, &item.id, budget, &plan.format);
            if let (Some(record), true) = (files.read_record(), files.mesh.is_file()) {
                done += 1;
                let out = &record.reconstruct["output_metrics"];
                let number = |v: &serde_json::Value| v.as_f64();
                let chamfer = number(&out["fidelity"]["chamfer_l2_over_diag"]);
                let cosine = number(&out["fidelity"]["normal_cosine"]);
                per_budget.entry(budget).or_default().push([
                    chamfer,
                    cosine,
                    number(&out["quality"]["aspect_ratio_median"]),
                    number(&out["topology"]["genus"]),
                    Some(record.seconds),
                ]);
                if let Some(chamfer) = chamfer {
                    worst.push(WorstItem {
                        id: item.id.clone(),
                        budget,
                        chamfer_over_diag: chamfer,
                        normal_cosine: cosine,
                    });
                }
            } else if let Some(failure) = files.read_failure() {
                *reasons
                    .entry(failure.reason.replace(&item.input, "INPUT"))
                    .or_default() += 1;
                failures.push(failure);
            } else {
                missing_items.push(format!("{}/{budget}", item.id));
            }
        }
    }
    let mut failures_by_reason: Vec<ReasonCount> = reasons
        .into_iter()
        .map(|(reason, count)| ReasonCount { reason, count })
        .collect();
    failures_by_reason.sort_by_key(|r| std::cmp::Reverse(r.count));
    worst.sort_by(|a, b| b.chamfer_over_diag.total_cmp(&a.chamfer_over_diag));
    worst.truncate(worst_count);
    let budgets = per_budget
        .into_iter()
        .map(|(budget, rows)| {
            let column = |k: usize| -> Vec<f64> { rows.iter().filter_map(|r| r[k]).collect() };
            BudgetSummary {
                budget,
                done: rows.len(),
                chamfer_over_diag: quantiles(&column(0)),
                normal_cosine: quantiles(&column(1)),
                aspect_ratio_median: quantiles(&column(2)),
                genus: quantiles(&column(3)),
                seconds: quantiles(&column(4)),
            }
        })
        .collect();
    Ok(BatchSummary {
        items: plan.items.len(),
        item_budgets,
        done,
        failed: failures.len(),
        missing: missing_items.len(),
        failures_by_reason,
        budgets,
        worst,
        failures,
        missing_items,
    })
}

/// The summary as Markdown.
pub fn markdown(summary: &BatchSummary) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Batch report\n");
    let _ = writeln!(
        md,
        "{} items, {} item budgets: **{} done**, **{} failed**, **{} missing**.\n",
        summary.items, summary.item_budgets, summary.done, summary.failed, summary.missing
    );
    if !summary.failures_by_reason.is_empty() {
        let _ = writeln!(
            md,
            "## Failures by reason\n\n| count | reason |\n| ---: | --- |"
        );
        for r in &summary.failures_by_reason {
            let _ = writeln!(md, "| {} | {} |", r.count, r.reason.replace('|', "\\|"));
        }
        md.push('\n');
    }
    for b in &summary.budgets {
        let _ = writeln!(
            md,
            "## {} faces ({} done)\n\n| metric | p10 | median | p90 |\n| --- | ---: | ---: | ---: |",
            b.budget, b.done
        );
        let rows = [
            ("Chamfer / diag", b.chamfer_over_diag, 6),
            ("normal cosine", b.normal_cosine, 4),
            ("aspect ratio (median)", b.aspect_ratio_median, 3),
            ("genus", b.genus, 0),
            ("seconds", b.seconds, 1),
        ];
        for (name, q, digits) in rows {
            match q {
                Some(q) => {
                    let _ = writeln!(
                        md,
                        "| {name} | {:.digits$} | {:.digits$} | {:.digits$} |",
                        q.p10, q.median, q.p90
                    );
                }
                None => {
                    let _ = writeln!(md, "| {name} | – | – | – |");
                }
            }
        }
        md.push('\n');
    }
    if !summary.worst.is_empty() {
        let _ = writeln!(
            md,
            "## Worst items\n\n| id | faces | Chamfer / diag | normal cosine |\n| --- | ---: | ---: | ---: |"
        );
        for w in &summary.worst {
            let cosine = w
                .normal_cosine
                .map_or("–".to_string(), |c| format!("{c:.4}"));
            let _ = writeln!(
                md,
                "| {} | {} | {:.6} | {cosine} |",
                w.id, w.budget, w.chamfer_over_diag
            );
        }
        md.push('\n');
    }
    if !summary.failures.is_empty() {
        let _ = writeln!(
            md,
            "## Failed\n\n| id | faces | seconds | reason |\n| --- | ---: | ---: | --- |"
        );
        for f in &summary.failures {
            let _ = writeln!(
                md,
                "| {} | {} | {:.1} | {} |",
                f.id,
                f.budget,
                f.seconds,
                f.reason.replace('|', "\\|")
            );
        }
        md.push('\n');
    }
    if !summary.missing_items.is_empty() {
        let _ = writeln!(md, "## Missing\n\n{}\n", summary.missing_items.join(", "));
    }
    md
}

/// Runs `roar batch-report`.
pub fn run(args: &BatchReportArgs) -> anyhow::Result<()> {
    let summary = summarize(&args.outdir, args.worst)?;
    let md = markdown(&summary);
    let json = serde_json::to_string_pretty(&summary)?;
    roar_io::atomic_write(&args.outdir.join("report.json"), |w| {
        w.write_all(json.as_bytes())
    })?;
    roar_io::atomic_write(&args.outdir.join("report.md"), |w| {
        w.write_all(md.as_bytes())
    })?;
    print!("{md}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::quantiles;

    #[test]
    fn nearest_rank_quantiles() {
        let v: Vec<f64> = (1..=10).map(f64::from).collect();
        let q = quantiles(&v).unwrap();
        assert_eq!((q.p10, q.median, q.p90, q.n), (1.0, 5.0, 9.0, 10));
        let one = quantiles(&[3.0, f64::NAN]).unwrap();
        assert_eq!((one.p10, one.median, one.p90, one.n), (3.0, 3.0, 3.0, 1));
        assert!(quantiles(&[]).is_none());
    }
}
