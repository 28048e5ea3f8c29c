//! `roar batch` and `roar batch-report` end to end on tiny items: bad manifests are refused up
//! front, failures are recorded and the batch goes on, a rerun skips what is done, and manifest
//! labels reach the records and the report's breakdown.

use std::path::Path;
use std::process::{Command, Output};

/// Settings that make an item take seconds: few views, coarse renders, a coarse init.
const TINY: &str = "[target]\nviews_per_axis = 2\nrender_resolution = 64\npoint_cloud_samples = 5000\n\
sharp_edge_samples = 1000\n[init]\ninit_resolution = 32\ninit_max_faces = 4000\n\
[loss]\nplanar_max_samples = 5000\n\
[optimize]\nworking_budget_min = 600\nsplit_interval = 3\nsmoothing_interval = 2\n";

fn roar(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_roar"))
        .current_dir(dir)
        .args(args)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .output()
        .expect("the roar binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn bad_batches_are_refused_up_front_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("dup.txt"), "a_b.obj\na/b.obj\n").unwrap();
    std::fs::write(d.join("ok.txt"), "a.obj\n").unwrap();
    std::fs::write(d.join("empty.txt"), "# nothing\n").unwrap();
    let cases: [(&[&str], &str); 7] = [
        (
            &["batch", "dup.txt", "-o", "out", "--faces", "200"],
            "same id",
        ),
        (
            &["batch", "empty.txt", "-o", "out", "--faces", "200"],
            "no items",
        ),
        (
            &["batch", "missing.txt", "-o", "out", "--faces", "200"],
            "cannot read",
        ),
        (
            &["batch", "ok.txt", "-o", "out", "--faces", "2x"],
            "--faces",
        ),
        (
            &[
                "batch", "ok.txt", "-o", "out", "--faces", "200", "--shard", "4/4",
            ],
            "0 <= I < K",
        ),
        (
            &[
                "batch", "ok.txt", "-o", "out", "--faces", "200", "--format", "xyz",
            ],
            "--format",
        ),
        (
            &[
                "batch", "ok.txt", "-o", "out", "--faces", "200", "--config", "no.toml",
            ],
            "no.toml",
        ),
    ];
    for (args, expected) in cases {
        let output = roar(d, args);
        let text = stderr(&output);
        assert!(!output.status.success(), "{args:?}");
        assert_eq!(text.trim_end().lines().count(), 1, "{args:?}: {text}");
        assert!(
            text.starts_with("roar: error: ") && text.contains(expected),
            "{args:?}: {text}"
        );
        assert!(!d.join("out").exists(), "{args:?} wrote output");
    }
    let report = roar(d, &["batch-report", "nowhere"]);
    assert!(!report.status.success());
    assert!(stderr(&report).contains("is nowhere the output of `roar batch`?"));
}

#[test]
fn a_batch_records_failures_goes_on_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(roar(d, &["example-soup", "chair.obj"]).status.success());
    std::fs::write(d.join("bad.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    std::fs::write(d.join("tiny.toml"), TINY).unwrap();
    std::fs::write(
        d.join("manifest.csv"),
        "id,path,faces,family\nchair,chair.obj,,furniture\nbroken,bad.obj,,junk\n\
         odd,chair.obj,201,furniture\n",
    )
    .unwrap();
    let args = [
        "batch",
        "manifest.csv",
        "-o",
        "out",
        "--faces",
        "200",
        "--config",
        "tiny.toml",
        "--iterations",
        "2",
    ];
    let first = roar(d, &args);
    let text = stderr(&first);
    assert!(!first.status.success(), "{text}");
    assert!(text.contains("chair 200 done in"), "{text}");
    let summary = text.trim_end().lines().last().unwrap();
    assert!(
        summary.starts_with(
            "roar: error: batch: 1 of 3 item budgets done (1 run, 0 already done), 2 failed"
        ),
        "{summary}"
    );
    let out = d.join("out");
    assert!(out.join("chair/200.obj").is_file() && out.join("chair/200.json").is_file());
    let log = std::fs::read_to_string(out.join("failures.jsonl")).unwrap();
    let failures: Vec<serde_json::Value> = log
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(failures.len(), 2, "{log}");
    assert_eq!(failures[0]["id"], "broken");
    assert!(
        failures[0]["reason"]
            .as_str()
            .unwrap()
            .starts_with("bad.obj:"),
        "{log}"
    );
    assert_eq!(failures[1]["budget"], 201);
    assert!(
        failures[1]["reason"].as_str().unwrap().contains("odd"),
        "{log}"
    );
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("chair/200.json")).unwrap())
            .unwrap();
    assert_eq!(record["labels"]["family"], "furniture");
    for key in ["input_hash", "config_hash", "build"] {
        assert_eq!(record[key].as_str().unwrap().len(), 16, "{key}");
    }
    assert_eq!(
        record["reconstruct"]["output_metrics"]["topology"]["faces"],
        200
    );
    let written = std::fs::metadata(out.join("chair/200.json"))
        .unwrap()
        .modified()
        .unwrap();

    // The rerun skips the finished item, retries the failures, and rewrites nothing finished.
    let second = roar(d, &args);
    let text = stderr(&second);
    assert!(text.contains("chair 200 already done"), "{text}");
    assert!(
        text.contains("1 of 3 item budgets done (0 run, 1 already done), 2 failed"),
        "{text}"
    );
    let rewritten = std::fs::metadata(out.join("chair/200.json"))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(written, rewritten);
    assert_eq!(
        std::fs::read_to_string(out.join("failures.jsonl"))
            .unwrap()
            .lines()
            .count(),
        4
    );

    // Another configuration is another result: the item is redone.
    let third = roar(d, &[&args[..], &["--seed", "7"]].concat());
    assert!(
        stderr(&third).contains("chair 200 done in"),
        "{}",
        stderr(&third)
    );

    let report = roar(d, &["batch-report", "out", "--by", "family"]);
    assert!(report.status.success(), "{}", stderr(&report));
    let md = String::from_utf8_lossy(&report.stdout);
    assert!(
        md.contains("3 items, 3 item budgets: **1 done**, **2 failed**, **0 missing**"),
        "{md}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["done"], 1);
    assert_eq!(json["failures_by_reason"].as_array().unwrap().len(), 2);
    assert_eq!(json["budgets"][0]["budget"], 200);
    assert_eq!(json["budgets"][0]["genus"]["median"], 0.0);
    assert_eq!(json["worst"][0]["id"], "chair");
    assert_eq!(json["slowest"][0]["id"], "chair");
    assert_eq!(json["slowest"][0]["label"], "furniture");
    let groups: Vec<(&str, u64, u64, u64)> = json["by_label"]["groups"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| {
            let count = |k: &str| g[k].as_u64().unwrap();
            (
                g["value"].as_str().unwrap(),
                g["budget"].as_u64().unwrap(),
                count("done"),
                count("failed"),
            )
        })
        .collect();
    assert_eq!(
        groups,
        [
            ("furniture", 200, 1, 0),
            ("furniture", 201, 0, 1),
            ("junk", 200, 0, 1)
        ]
    );
    assert!(md.contains("## By family"), "{md}");
    assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), md);
}
