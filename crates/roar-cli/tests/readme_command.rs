//! The README's first command as a person runs it, but with stdout and stderr captured (not a
//! terminal): it must speak in a few lines, the JSON going only to `--report` (release mode, run
//! by `.ci/run` with `--ignored`).

use std::path::PathBuf;
use std::process::Command;

#[test]
#[ignore = "a full reconstruction; run in release by .ci/run"]
fn the_readme_command_prints_a_short_summary_and_writes_the_report_to_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let example = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/chair_soup.obj");
    let (mesh, report) = (dir.path().join("chair.obj"), dir.path().join("chair.json"));
    let output = Command::new(env!("CARGO_BIN_EXE_roar"))
        .arg("reconstruct")
        .arg(&example)
        .arg("-o")
        .arg(&mesh)
        .args(["--faces", "1000", "--report"])
        .arg(&report)
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr),
    );
    assert!(output.status.success(), "{stderr}");
    let lines = stdout.lines().count() + stderr.lines().count();
    assert!(lines <= 15, "{lines} lines:\n{stdout}{stderr}");
    assert!(stdout.contains("1000 faces, closed"), "{stdout}");
    assert!(stdout.contains(&report.display().to_string()), "{stdout}");
    assert!(!stdout.contains('{'), "the JSON went to stdout:\n{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["output_metrics"]["topology"]["faces"], 1000);
}
