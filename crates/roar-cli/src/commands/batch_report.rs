//! `roar batch-report OUTDIR`: the summary of a batch's output folder, as Markdown on stdout and
//! in `OUTDIR/report.md`, and as JSON in `OUTDIR/report.json`: items done, failed and missing,
//! failures grouped by reason, the p10, median and p90 of each metric per budget, optionally the
//! same broken down by a manifest label (`--by family`), the worst items by Chamfer distance and
//! the slowest items.
//!
//! It reads only files: `OUTDIR/manifest.json` (the plan a batch writes, with every item's
//! labels) and each item's `<budget>.json` or `<budget>.failure.json`, so it can run while shards
//! are still going.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::Args;
use serde::Serialize;

use crate::batch::layout::{FailureRecord, ItemFiles, ItemRecord, Plan, plan_path};

/// Arguments of `roar batch-report`.
#[derive(Args, Debug)]
pub struct BatchReportArgs {
    /// The output folder of `roar batch`.
    pub outdir: PathBuf,
    /// How many of the worst items to list.
    #[arg(long, default_value_t = 10)]
    pub worst: usize,
    /// How many of the slowest finished items to list.
    #[arg(long, default_value_t = 10)]
    pub slowest: usize,
    /// A manifest label (an extra column, e.g. `family`) to break the results down by.
    #[arg(long, value_name = "LABEL")]
    pub by: Option<String>,
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
    /// Counts and distributions per value of the `--by` label and budget.
    pub by_label: Option<Breakdown>,
    /// The worst finished item budgets by Chamfer/diag, worst first.
    pub worst: Vec<ItemLine>,
    /// The slowest finished item budgets, slowest first.
    pub slowest: Vec<ItemLine>,
    /// Every failure.
    pub failures: Vec<FailureRecord>,
    /// Every missing item budget as `id/budget`.
    pub missing_items: Vec<String>,
}

/// How many failures share one reason, and which.
#[derive(Debug, Serialize)]
pub struct ReasonCount {
    /// The reason.
    pub reason: String,
    /// How many item budgets failed with it.
    pub count: usize,
    /// Those item budgets as `id/budget`, in manifest order.
    pub items: Vec<String>,
}

/// The distributions of a set of finished item budgets; `None` where no item has the metric.
#[derive(Debug, Serialize)]
pub struct Metrics {
    /// Sampled Chamfer L2 over the reference's bounding-box diagonal.
    pub chamfer_over_diag: Option<Quantiles>,
    /// Chamfer L2 over the diagonal without the sampling floor (reports that predate it lack it).
    pub chamfer_exact_over_diag: Option<Quantiles>,
    /// Mean absolute normal cosine to the input: a soup's orientation is arbitrary, so the
    /// signed cosine says nothing about it.
    pub normal_cosine_abs: Option<Quantiles>,
    /// Median triangle aspect ratio of each output.
    pub aspect_ratio_median: Option<Quantiles>,
    /// Genus of each output.
    pub genus: Option<Quantiles>,
    /// Seconds of each item's child process.
    pub seconds: Option<Quantiles>,
}

/// The distributions of one budget's finished items.
#[derive(Debug, Serialize)]
pub struct BudgetSummary {
    /// The face budget.
    pub budget: usize,
    /// Finished items at this budget.
    pub done: usize,
    /// Their distributions.
    #[serde(flatten)]
    pub metrics: Metrics,
}

/// The results broken down by one label.
#[derive(Debug, Serialize)]
pub struct Breakdown {
    /// The label's name.
    pub label: String,
    /// One group per label value and budget, by value then budget.
    pub groups: Vec<GroupSummary>,
}

/// The item budgets of one label value at one budget.
#[derive(Debug, Serialize)]
pub struct GroupSummary {
    /// The label's value; `None` for items without it.
    pub value: Option<String>,
    /// The face budget.
    pub budget: usize,
    /// Finished item budgets.
    pub done: usize,
    /// Failed item budgets.
    pub failed: usize,
    /// Missing item budgets.
    pub missing: usize,
    /// Distributions of the finished ones.
    #[serde(flatten)]
    pub metrics: Metrics,
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

/// One finished item budget, as the worst and slowest lists show it.
#[derive(Debug, Clone, Serialize)]
pub struct ItemLine {
    /// Its id.
    pub id: String,
    /// Its budget.
    pub budget: usize,
    /// Its value of the `--by` label, if given and present.
    pub label: Option<String>,
    /// Seconds of its child process.
    pub seconds: f64,
    /// Sampled Chamfer L2 over the reference diagonal, if measured.
    pub chamfer_over_diag: Option<f64>,
    /// Chamfer L2 over the diagonal without the sampling floor, if measured.
    pub chamfer_exact_over_diag: Option<f64>,
    /// Mean absolute normal cosine, if measured.
    pub normal_cosine_abs: Option<f64>,
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

/// A finished item budget with every figure the report uses.
struct Finished {
    line: ItemLine,
    aspect_ratio_median: Option<f64>,
    genus: Option<f64>,
}

impl Finished {
    /// The figures of a record; a metric its report lacks is `None`.
    fn new(record: &ItemRecord, label: Option<String>) -> Self {
        let out = &record.reconstruct["output_metrics"];
        let fidelity = &out["fidelity"];
        Self {
            line: ItemLine {
                id: record.id.clone(),
                budget: record.budget,
                label,
                seconds: record.seconds,
                chamfer_over_diag: fidelity["chamfer_l2_over_diag"].as_f64(),
                chamfer_exact_over_diag: fidelity["chamfer_exact_over_diag"].as_f64(),
                normal_cosine_abs: fidelity["normal_cosine_abs"].as_f64(),
            },
            aspect_ratio_median: out["quality"]["aspect_ratio_median"].as_f64(),
            genus: out["topology"]["genus"].as_f64(),
        }
    }
}

impl Metrics {
    fn of(items: &[&Finished]) -> Self {
        let q = |figure: fn(&Finished) -> Option<f64>| {
            quantiles(&items.iter().filter_map(|f| figure(f)).collect::<Vec<_>>())
        };
        Self {
            chamfer_over_diag: q(|f| f.line.chamfer_over_diag),
            chamfer_exact_over_diag: q(|f| f.line.chamfer_exact_over_diag),
            normal_cosine_abs: q(|f| f.line.normal_cosine_abs),
            aspect_ratio_median: q(|f| f.aspect_ratio_median),
            genus: q(|f| f.genus),
            seconds: q(|f| Some(f.line.seconds)),
        }
    }
}

/// Reads an output folder into its summary. Refuses a folder without a plan, and a `--by`
/// label that no item of the plan has (most likely a typo).
pub fn summarize(outdir: &Path, args: &BatchReportArgs) -> anyhow::Result<BatchSummary> {
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
    let by = args.by.as_ref().map(|b| b.to_ascii_lowercase());
    if let Some(by) = &by {
        check_label(&plan, by)?;
    }
    let mut item_budgets = 0;
    let mut finished = Vec::new();
    let mut failures = Vec::new();
    let mut missing_items = Vec::new();
    let mut reasons: BTreeMap<String, Vec<String>> = BTreeMap::new();
    // Per label value and budget: done, failed and missing item budgets.
    let mut counts: BTreeMap<(Option<String>, usize), [usize; 3]> = BTreeMap::new();
    for item in &plan.items {
        let label = by.as_ref().and_then(|b| item.labels.get(b).cloned());
        for &budget in &item.budgets {
            item_budgets += 1;
            let files = ItemFiles::new(outdir, &item.id, budget, &plan.format);
            let outcome = if let (Some(record), true) = (files.read_record(), files.mesh.is_file())
            {
                finished.push(Finished::new(&record, label.clone()));
                0
            } else if let Some(failure) = files.read_failure() {
                reasons
                    .entry(failure.reason.replace(&item.input, "INPUT"))
                    .or_default()
                    .push(format!("{}/{budget}", item.id));
                failures.push(failure);
                1
            } else {
                missing_items.push(format!("{}/{budget}", item.id));
                2
            };
            if by.is_some() {
                counts.entry((label.clone(), budget)).or_default()[outcome] += 1;
            }
        }
    }
    let mut failures_by_reason: Vec<ReasonCount> = reasons
        .into_iter()
        .map(|(reason, items)| ReasonCount {
            reason,
            count: items.len(),
            items,
        })
        .collect();
    failures_by_reason.sort_by_key(|r| std::cmp::Reverse(r.count));
    let mut budgets: BTreeMap<usize, Vec<&Finished>> = BTreeMap::new();
    for f in &finished {
        budgets.entry(f.line.budget).or_default().push(f);
    }
    let budgets = budgets
        .into_iter()
        .map(|(budget, items)| BudgetSummary {
            budget,
            done: items.len(),
            metrics: Metrics::of(&items),
        })
        .collect();
    let by_label = by.map(|label| Breakdown {
        label,
        groups: counts
            .into_iter()
            .map(|((value, budget), [done, failed, missing])| {
                let items: Vec<&Finished> = finished
                    .iter()
                    .filter(|f| f.line.budget == budget && f.line.label == value)
                    .collect();
                GroupSummary {
                    value,
                    budget,
                    done,
                    failed,
                    missing,
                    metrics: Metrics::of(&items),
                }
            })
            .collect(),
    });
    let mut worst: Vec<ItemLine> = finished
        .iter()
        .filter(|f| f.line.chamfer_over_diag.is_some())
        .map(|f| f.line.clone())
        .collect();
    // Every line kept has a Chamfer; the default only satisfies the type.
    let chamfer = |l: &ItemLine| l.chamfer_over_diag.unwrap_or(0.0);
    worst.sort_by(|a, b| chamfer(b).total_cmp(&chamfer(a)));
    worst.truncate(args.worst);
    let mut slowest: Vec<ItemLine> = finished.iter().map(|f| f.line.clone()).collect();
    slowest.sort_by(|a, b| b.seconds.total_cmp(&a.seconds));
    slowest.truncate(args.slowest);
    Ok(BatchSummary {
        items: plan.items.len(),
        item_budgets,
        done: finished.len(),
        failed: failures.len(),
        missing: missing_items.len(),
        failures_by_reason,
        budgets,
        by_label,
        worst,
        slowest,
        failures,
        missing_items,
    })
}

/// Refuses a label no item of the plan has, naming the labels it does have.
fn check_label(plan: &Plan, label: &str) -> anyhow::Result<()> {
    if plan.items.iter().any(|i| i.labels.contains_key(label)) {
        return Ok(());
    }
    let mut known: Vec<&str> = plan
        .items
        .iter()
        .flat_map(|i| i.labels.keys().map(String::as_str))
        .collect();
    known.sort_unstable();
    known.dedup();
    if known.is_empty() {
        bail!("--by {label}: the batch's manifest has no label columns");
    }
    bail!(
        "--by {label}: no item has that label (labels: {})",
        known.join(", ")
    );
}

/// A number with `digits` decimals, or `–` when absent.
fn number(value: Option<f64>, digits: usize) -> String {
    value.map_or("–".to_string(), |v| format!("{v:.digits$}"))
}

/// A Markdown table cell: pipes escaped.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// How many item ids a reason lists in Markdown (the JSON lists them all).
const REASON_ITEMS: usize = 10;

/// The summary as Markdown. The exact Chamfer appears only when some report has it.
pub fn markdown(summary: &BatchSummary) -> String {
    let exact = summary
        .budgets
        .iter()
        .any(|b| b.metrics.chamfer_exact_over_diag.is_some());
    let label = summary.by_label.as_ref().map(|b| b.label.as_str());
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
            "## Failures by reason\n\n| count | reason | items |\n| ---: | --- | --- |"
        );
        for r in &summary.failures_by_reason {
            let mut items = r.items[..r.items.len().min(REASON_ITEMS)].join(", ");
            if r.items.len() > REASON_ITEMS {
                let _ = write!(items, " and {} more", r.items.len() - REASON_ITEMS);
            }
            let _ = writeln!(md, "| {} | {} | {items} |", r.count, cell(&r.reason));
        }
        md.push('\n');
    }
    for b in &summary.budgets {
        let _ = writeln!(
            md,
            "## {} faces ({} done)\n\n| metric | p10 | median | p90 |\n| --- | ---: | ---: | ---: |",
            b.budget, b.done
        );
        let m = &b.metrics;
        let rows = [
            ("Chamfer / diag", m.chamfer_over_diag, 6),
            ("exact Chamfer / diag", m.chamfer_exact_over_diag, 6),
            ("abs normal cosine", m.normal_cosine_abs, 4),
            ("aspect ratio (median)", m.aspect_ratio_median, 3),
            ("genus", m.genus, 0),
            ("seconds", m.seconds, 1),
        ];
        for (name, q, digits) in rows {
            if name.starts_with("exact") && !exact {
                continue;
            }
            let _ = writeln!(
                md,
                "| {name} | {} | {} | {} |",
                number(q.map(|q| q.p10), digits),
                number(q.map(|q| q.median), digits),
                number(q.map(|q| q.p90), digits)
            );
        }
        md.push('\n');
    }
    if let Some(breakdown) = &summary.by_label {
        let mut header = vec![
            breakdown.label.as_str(),
            "faces",
            "done",
            "failed",
            "missing",
            "median s",
            "p90 s",
            "median Chamfer / diag",
        ];
        if exact {
            header.push("median exact Chamfer / diag");
        }
        header.push("median abs normal cosine");
        let median = |q: Option<Quantiles>, digits| number(q.map(|q| q.median), digits);
        let rows: Vec<Vec<String>> = breakdown
            .groups
            .iter()
            .map(|g| {
                let m = &g.metrics;
                let mut row = vec![
                    cell(g.value.as_deref().unwrap_or("–")),
                    g.budget.to_string(),
                    g.done.to_string(),
                    g.failed.to_string(),
                    g.missing.to_string(),
                    median(m.seconds, 1),
                    number(m.seconds.map(|q| q.p90), 1),
                    median(m.chamfer_over_diag, 6),
                ];
                if exact {
                    row.push(median(m.chamfer_exact_over_diag, 6));
                }
                row.push(median(m.normal_cosine_abs, 4));
                row
            })
            .collect();
        table(
            &mut md,
            &format!("By {}", breakdown.label),
            &header,
            1,
            &rows,
        );
    }
    item_table(&mut md, "Worst items", &summary.worst, label, exact);
    item_table(&mut md, "Slowest items", &summary.slowest, label, exact);
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
                cell(&f.reason)
            );
        }
        md.push('\n');
    }
    if !summary.missing_items.is_empty() {
        let _ = writeln!(md, "## Missing\n\n{}\n", summary.missing_items.join(", "));
    }
    md
}

/// A table of item lines under `title`, with a column for the `--by` label if given and for the
/// exact Chamfer if any report has it; nothing when there are no lines.
fn item_table(md: &mut String, title: &str, lines: &[ItemLine], label: Option<&str>, exact: bool) {
    if lines.is_empty() {
        return;
    }
    let mut header = vec!["id"];
    header.extend(label);
    header.extend(["faces", "seconds", "Chamfer / diag"]);
    if exact {
        header.push("exact Chamfer / diag");
    }
    header.push("abs normal cosine");
    let rows: Vec<Vec<String>> = lines
        .iter()
        .map(|l| {
            let mut row = vec![l.id.clone()];
            if label.is_some() {
                row.push(cell(l.label.as_deref().unwrap_or("–")));
            }
            row.push(l.budget.to_string());
            row.push(format!("{:.1}", l.seconds));
            row.push(number(l.chamfer_over_diag, 6));
            if exact {
                row.push(number(l.chamfer_exact_over_diag, 6));
            }
            row.push(number(l.normal_cosine_abs, 4));
            row
        })
        .collect();
    table(md, title, &header, 1 + usize::from(label.is_some()), &rows);
}

/// A Markdown table under a `## title` heading: its first `left` columns (text) left-aligned,
/// the others (numbers) right-aligned.
fn table(md: &mut String, title: &str, header: &[&str], left: usize, rows: &[Vec<String>]) {
    let align: Vec<&str> = (0..header.len())
        .map(|i| if i < left { "---" } else { "---:" })
        .collect();
    let _ = writeln!(
        md,
        "## {title}\n\n| {} |\n| {} |",
        header.join(" | "),
        align.join(" | ")
    );
    for row in rows {
        let _ = writeln!(md, "| {} |", row.join(" | "));
    }
    md.push('\n');
}

/// Runs `roar batch-report`.
pub fn run(args: &BatchReportArgs) -> anyhow::Result<()> {
    let summary = summarize(&args.outdir, args)?;
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
    use super::*;
    use crate::batch::layout::ItemRecord;
    use serde_json::json;

    #[test]
    fn nearest_rank_quantiles() {
        let v: Vec<f64> = (1..=10).map(f64::from).collect();
        let q = quantiles(&v).unwrap();
        assert_eq!((q.p10, q.median, q.p90, q.n), (1.0, 5.0, 9.0, 10));
        let one = quantiles(&[3.0, f64::NAN]).unwrap();
        assert_eq!((one.p10, one.median, one.p90, one.n), (3.0, 3.0, 3.0, 1));
        assert!(quantiles(&[]).is_none());
    }

    /// A fidelity section as `roar reconstruct` writes it; `exact` only in newer reports.
    fn fidelity(chamfer: f64, exact: Option<f64>, cosine_abs: f64) -> serde_json::Value {
        let mut f = json!({
            "chamfer_l2_over_diag": chamfer,
            // A soup's orientation is arbitrary: the signed cosine is about 0.
            "normal_cosine": 0.01,
            "normal_cosine_abs": cosine_abs,
        });
        if let Some(exact) = exact {
            f["chamfer_exact_over_diag"] = json!(exact);
        }
        f
    }

    /// Writes a finished item budget: its mesh and its record.
    fn done(outdir: &Path, id: &str, budget: usize, seconds: f64, fidelity: serde_json::Value) {
        let files = ItemFiles::new(outdir, id, budget, "obj");
        std::fs::create_dir_all(&files.folder).unwrap();
        std::fs::write(&files.mesh, "").unwrap();
        let record = ItemRecord {
            id: id.into(),
            budget,
            input: format!("in/{id}.obj"),
            input_hash: "i".into(),
            config_hash: "c".into(),
            build: "b".into(),
            seconds,
            labels: BTreeMap::new(),
            reconstruct: json!({"output_metrics": {
                "fidelity": fidelity,
                "quality": {"aspect_ratio_median": 1.5},
                "topology": {"genus": 0},
            }}),
        };
        std::fs::write(&files.record, serde_json::to_string(&record).unwrap()).unwrap();
    }

    /// Writes a failed item budget.
    fn failed(outdir: &Path, id: &str, budget: usize, reason: &str) {
        let files = ItemFiles::new(outdir, id, budget, "obj");
        std::fs::create_dir_all(&files.folder).unwrap();
        let failure = FailureRecord {
            id: id.into(),
            budget,
            reason: reason.into(),
            seconds: 5.0,
        };
        std::fs::write(&files.failure, serde_json::to_string(&failure).unwrap()).unwrap();
    }

    /// A batch of five items at 500 faces: two `cad` items done, one `cad` item failed, a
    /// `furniture` item failed for another reason, and an item of a plan written before labels
    /// (no `labels` key) missing.
    fn fabricated(exact: bool) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path();
        let item = |id: &str, family: Option<&str>| {
            let mut i = json!({"id": id, "input": format!("in/{id}.obj"), "budgets": [500]});
            if let Some(family) = family {
                i["labels"] = json!({"family": family, "input_faces": "3652"});
            }
            i
        };
        let plan = json!({"manifest": "m.tsv", "format": "obj", "items": [
            item("gear", Some("cad")),
            item("bracket", Some("cad")),
            item("hinge", Some("cad")),
            item("chair", Some("furniture")),
            item("old", None),
        ]});
        std::fs::write(plan_path(out), plan.to_string()).unwrap();
        let exact = |e: f64| exact.then_some(e);
        done(out, "gear", 500, 2.0, fidelity(0.01, exact(0.008), 0.9));
        done(out, "bracket", 500, 9.0, fidelity(0.03, exact(0.02), 0.8));
        failed(out, "hinge", 500, "timed out after 5 s");
        failed(out, "chair", 500, "in/chair.obj: bad header");
        dir
    }

    fn args(outdir: &Path, by: Option<&str>) -> BatchReportArgs {
        BatchReportArgs {
            outdir: outdir.to_path_buf(),
            worst: 10,
            slowest: 1,
            by: by.map(str::to_string),
        }
    }

    #[test]
    fn budgets_report_the_absolute_normal_cosine_and_the_exact_chamfer() {
        let dir = fabricated(true);
        let summary = summarize(dir.path(), &args(dir.path(), None)).unwrap();
        let m = &summary.budgets[0].metrics;
        let cosine = m.normal_cosine_abs.unwrap();
        assert_eq!((cosine.p10, cosine.p90), (0.8, 0.9));
        let exact = m.chamfer_exact_over_diag.unwrap();
        assert_eq!((exact.p10, exact.p90), (0.008, 0.02));
        assert_eq!(m.seconds.unwrap().p90, 9.0);
        assert!(summary.by_label.is_none());
        let md = markdown(&summary);
        assert!(
            md.contains("| abs normal cosine | 0.8000 | 0.8000 | 0.9000 |"),
            "{md}"
        );
        assert!(md.contains("| exact Chamfer / diag | 0.008000 |"), "{md}");
        let json = serde_json::to_value(&summary).unwrap();
        assert_eq!(json["budgets"][0]["normal_cosine_abs"]["p90"], 0.9);
        assert_eq!(json["budgets"][0]["chamfer_exact_over_diag"]["n"], 2);
        assert!(json["budgets"][0].get("normal_cosine").is_none());
    }

    #[test]
    fn reports_without_the_exact_chamfer_leave_its_column_out() {
        let dir = fabricated(false);
        let summary = summarize(dir.path(), &args(dir.path(), Some("family"))).unwrap();
        assert!(summary.budgets[0].metrics.chamfer_exact_over_diag.is_none());
        assert_eq!(summary.worst[0].chamfer_exact_over_diag, None);
        let md = markdown(&summary);
        assert!(!md.contains("exact"), "{md}");
        assert!(md.contains("| Chamfer / diag | 0.010000 |"), "{md}");
    }

    #[test]
    fn by_label_counts_and_measures_each_value_per_budget() {
        let dir = fabricated(true);
        // Column names are lowercased, so the label matches in any case.
        let summary = summarize(dir.path(), &args(dir.path(), Some("Family"))).unwrap();
        let breakdown = summary.by_label.as_ref().unwrap();
        assert_eq!(breakdown.label, "family");
        let groups: Vec<(Option<&str>, usize, usize, usize, usize)> = breakdown
            .groups
            .iter()
            .map(|g| (g.value.as_deref(), g.budget, g.done, g.failed, g.missing))
            .collect();
        assert_eq!(
            groups,
            [
                (None, 500, 0, 0, 1),
                (Some("cad"), 500, 2, 1, 0),
                (Some("furniture"), 500, 0, 1, 0),
            ]
        );
        let cad = &breakdown.groups[1].metrics;
        assert_eq!(cad.seconds.unwrap().median, 2.0);
        assert!(breakdown.groups[2].metrics.seconds.is_none());
        let md = markdown(&summary);
        assert!(
            md.contains(
                "## By family\n\n| family | faces | done | failed | missing | median s | p90 s | \
                 median Chamfer / diag | median exact Chamfer / diag | median abs normal cosine |"
            ),
            "{md}"
        );
        assert!(
            md.contains("| cad | 500 | 2 | 1 | 0 | 2.0 | 9.0 | 0.010000 | 0.008000 | 0.8000 |"),
            "{md}"
        );
        assert!(
            md.contains("| furniture | 500 | 0 | 1 | 0 | – | – | – | – | – |"),
            "{md}"
        );
        assert!(md.contains("| – | 500 | 0 | 0 | 1 |"), "{md}");
    }

    #[test]
    fn the_slowest_items_come_first_with_their_label() {
        let dir = fabricated(true);
        let summary = summarize(dir.path(), &args(dir.path(), Some("family"))).unwrap();
        assert_eq!(summary.slowest.len(), 1, "--slowest 1");
        assert_eq!(summary.slowest[0].id, "bracket");
        assert_eq!(summary.slowest[0].label.as_deref(), Some("cad"));
        assert_eq!(summary.worst[0].id, "bracket");
        assert_eq!(summary.worst[1].id, "gear");
        let md = markdown(&summary);
        assert!(
            md.contains(
                "## Slowest items\n\n| id | family | faces | seconds | Chamfer / diag | \
                 exact Chamfer / diag | abs normal cosine |\n| --- | --- | ---: |"
            ),
            "{md}"
        );
        assert!(
            md.contains("| bracket | cad | 500 | 9.0 | 0.030000 | 0.020000 | 0.8000 |"),
            "{md}"
        );
    }

    #[test]
    fn failures_by_reason_name_their_items() {
        let dir = fabricated(true);
        let summary = summarize(dir.path(), &args(dir.path(), None)).unwrap();
        let reasons: Vec<(&str, &[String])> = summary
            .failures_by_reason
            .iter()
            .map(|r| (r.reason.as_str(), r.items.as_slice()))
            .collect();
        assert_eq!(
            reasons,
            [
                ("INPUT: bad header", &["chair/500".to_string()][..]),
                ("timed out after 5 s", &["hinge/500".to_string()][..]),
            ]
        );
        let md = markdown(&summary);
        assert!(
            md.contains("| 1 | timed out after 5 s | hinge/500 |"),
            "{md}"
        );
    }

    #[test]
    fn an_unknown_label_is_refused_naming_the_known_ones() {
        let dir = fabricated(true);
        let err = summarize(dir.path(), &args(dir.path(), Some("famly"))).unwrap_err();
        assert_eq!(
            err.to_string(),
            "--by famly: no item has that label (labels: family, input_faces)"
        );
    }
}
