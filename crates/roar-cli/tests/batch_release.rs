//! A dataset of 40 tiny items run as 4 concurrent shards, with 3 items that fail (an unreadable
//! file, an item past its timeout, `--faces 2`); one shard is killed with SIGTERM in the middle
//! of an item and every shard is rerun. Every good item must be done exactly once, the failures
//! listed with their reasons, and `batch-report` must agree. Release only: run with
//! `cargo test --release -p roar-cli --test batch_release -- --ignored`.

use std::collections::HashMap;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The toy config; `level_window = 0` makes every item run all its iterations, so the item past
/// its timeout and the one the kill lands in stay slow.
const TINY: &str = "[target]\nviews_per_axis = 2\nrender_resolution = 64\npoint_cloud_samples = 5000\n\
sharp_edge_samples = 1000\n[init]\ninit_resolution = 32\ninit_max_faces = 4000\n\
[loss]\nplanar_max_samples = 5000\n\
[optimize]\nworking_budget_min = 600\nsplit_interval = 3\nsmoothing_interval = 2\nlevel_window = 0\n";

/// Positions (0-based) of the failing items; none is in shard 1, the one that is killed.
const BAD_FILE: usize = 8;
const TOO_SLOW: usize = 6;
const TWO_FACES: usize = 3;
/// An item of shard 1 with more iterations, so the kill lands in the middle of one.
const LONGER: usize = 9;

fn spawn_shard(dir: &Path, shard: usize, log: &Path) -> Child {
    let log = std::fs::File::create(log).unwrap();
    let shard = format!("{shard}/4");
    Command::new(env!("CARGO_BIN_EXE_roar"))
        .current_dir(dir)
        .args(["batch", "manifest.csv", "-o", "out", "--faces", "200"])
        .args([
            "--config",
            "tiny.toml",
            "--iterations",
            "3",
            "--shard",
            &shard,
        ])
        .env_remove("SLURM_ARRAY_TASK_ID")
        .stdout(Stdio::null())
        .stderr(log)
        // Its own process group, so a signal reaches the batch and its child, as Ctrl-C and
        // SLURM's scancel do.
        .process_group(0)
        .spawn()
        .unwrap()
}

fn id(position: usize) -> String {
    format!("item{position:02}")
}

#[test]
#[ignore = "release: 40 items, 4 shards, a kill and a rerun"]
fn forty_items_in_four_shards_survive_a_killed_shard() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let soup = roar::example::chair_soup();
    for ext in ["obj", "ply", "off", "stl"] {
        roar_io::write_mesh(&d.join(format!("chair.{ext}")), &soup).unwrap();
    }
    std::fs::write(d.join("broken.obj"), "this is not a mesh\n").unwrap();
    std::fs::write(d.join("tiny.toml"), TINY).unwrap();
    let mut manifest = String::from("id,path,faces,iterations,seed,timeout\n");
    for position in 0..40 {
        let ext = ["obj", "ply", "off", "stl"][position % 4];
        let row = match position {
            BAD_FILE => "broken.obj,,,,".to_string(),
            TOO_SLOW => "chair.obj,,5000,,2".to_string(),
            TWO_FACES => "chair.obj,2,,,".to_string(),
            LONGER => format!("chair.{ext},,40,{position},"),
            _ => format!("chair.{ext},,,{position},"),
        };
        manifest.push_str(&format!("{},{row}\n", id(position)));
    }
    std::fs::write(d.join("manifest.csv"), manifest).unwrap();
    let out = d.join("out");
    let record = |position: usize| out.join(id(position)).join("200.json");

    // First run: four shards at once; shard 1 is killed once it has finished two items and is
    // in the middle of its third.
    let mut shards: Vec<Child> = (0..4)
        .map(|s| spawn_shard(d, s, &d.join(format!("run1-{s}.log"))))
        .collect();
    let shard1: Vec<usize> = (0..40).filter(|p| p % 4 == 1).collect();
    let started = Instant::now();
    let interrupted = loop {
        let done: Vec<usize> = shard1
            .iter()
            .copied()
            .filter(|&p| record(p).exists())
            .collect();
        let running = shard1
            .iter()
            .copied()
            .find(|&p| !record(p).exists() && out.join(id(p)).join("200.log").exists());
        if done.len() >= 2
            && let Some(p) = running
        {
            break p;
        }
        assert!(
            started.elapsed() < Duration::from_secs(300),
            "shard 1 never got going"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    let group = shards[1].id();
    let kill = Command::new("kill")
        .args(["-TERM", "--", &format!("-{group}")])
        .status()
        .unwrap();
    assert!(kill.success());
    let killed = shards[1].wait().unwrap();
    assert!(!killed.success(), "the killed shard exited {killed:?}");
    assert!(
        !record(interrupted).exists(),
        "item {interrupted} finished despite the kill"
    );
    let statuses: Vec<bool> = shards
        .iter_mut()
        .enumerate()
        .filter(|(s, _)| *s != 1)
        .map(|(_, c)| c.wait().unwrap().success())
        .collect();
    // Shards 0, 2 and 3 each hold one failing item, so each exits non-zero.
    assert_eq!(statuses, [false, false, false]);

    // Second run: every shard again, one after the other.
    for s in 0..4 {
        let status = spawn_shard(d, s, &d.join(format!("run2-{s}.log")))
            .wait()
            .unwrap();
        assert_eq!(
            status.success(),
            s == 1,
            "shard {s} of the rerun: {status:?}"
        );
    }

    // Every good item was done exactly once over both runs (one "done" line per record write).
    let mut done_lines: HashMap<String, usize> = HashMap::new();
    for run in 1..=2 {
        for s in 0..4 {
            let log = std::fs::read_to_string(d.join(format!("run{run}-{s}.log"))).unwrap();
            for line in log.lines().filter(|l| l.contains(" 200 done in ")) {
                let name = line.split_whitespace().nth(3).unwrap().to_string();
                *done_lines.entry(name).or_default() += 1;
            }
        }
    }
    let failing = [BAD_FILE, TOO_SLOW, TWO_FACES];
    for position in (0..40).filter(|p| !failing.contains(p)) {
        assert_eq!(done_lines.get(&id(position)), Some(&1), "item {position}");
        assert!(record(position).is_file() && out.join(id(position)).join("200.obj").is_file());
    }
    assert_eq!(done_lines.len(), 37, "{done_lines:?}");
    let leftovers: Vec<_> = walk(&out)
        .into_iter()
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            name.contains(".partial.") || name.ends_with(".tmp")
        })
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    // The failures with their reasons, in each shard's own log.
    let failures = |shard: usize| -> Vec<serde_json::Value> {
        let log =
            std::fs::read_to_string(out.join(format!("failures-{shard}-of-4.jsonl"))).unwrap();
        log.lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    for (position, shard, reason) in [
        (BAD_FILE, 0, "broken.obj: "),
        (TOO_SLOW, 2, "timed out after 2 s"),
        (
            TWO_FACES,
            3,
            "faces = 2 is below the smallest reachable budget, 4 faces",
        ),
    ] {
        let logged = failures(shard);
        assert_eq!(logged.len(), 2, "one per run: {logged:?}");
        for f in &logged {
            assert_eq!(f["id"], id(position));
            assert!(f["reason"].as_str().unwrap().contains(reason), "{f}");
        }
    }
    assert!(!out.join("failures-1-of-4.jsonl").exists() || failures(1).is_empty());

    let report = Command::new(env!("CARGO_BIN_EXE_roar"))
        .args(["batch-report", "out"])
        .current_dir(d)
        .output()
        .unwrap();
    assert!(report.status.success());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["items"], 40);
    assert_eq!(json["done"], 37);
    assert_eq!(json["failed"], 3);
    assert_eq!(json["missing"], 0);
    let mut failed_ids: Vec<String> = json["failures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["id"].as_str().unwrap().to_string())
        .collect();
    failed_ids.sort();
    assert_eq!(failed_ids, [id(TWO_FACES), id(TOO_SLOW), id(BAD_FILE)]);
    let by_budget: Vec<(u64, u64)> = json["budgets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| (b["budget"].as_u64().unwrap(), b["done"].as_u64().unwrap()))
        .collect();
    assert_eq!(by_budget, [(200, 37)]);
    let chamfer = &json["budgets"][0]["chamfer_over_diag"];
    let (p10, median, p90) = (
        chamfer["p10"].as_f64().unwrap(),
        chamfer["median"].as_f64().unwrap(),
        chamfer["p90"].as_f64().unwrap(),
    );
    assert!(
        0.0 < p10 && p10 <= median && median <= p90 && p90 < 0.05,
        "{chamfer}"
    );
    assert_eq!(json["budgets"][0]["genus"]["median"], 0.0);
}

fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(walk(&path));
        } else {
            out.push(path);
        }
    }
    out
}
