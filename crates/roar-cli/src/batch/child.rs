//! One item in a child process: started, watched for its time limit and resident memory, and
//! killed when it passes either, so only that item dies and the batch goes on.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// How to run and guard one child process.
#[derive(Debug, Clone)]
pub struct ChildOptions {
    /// The executable.
    pub program: PathBuf,
    /// Its arguments.
    pub args: Vec<OsString>,
    /// Extra environment variables.
    pub env: Vec<(String, String)>,
    /// Wall-clock limit.
    pub timeout: Option<Duration>,
    /// Limit on the resident set size in bytes (read from `/proc/PID/status`).
    pub max_memory: Option<u64>,
    /// File that receives the child's stderr (its stdout is discarded).
    pub log: PathBuf,
}

/// How a child ended.
#[derive(Debug, Clone, PartialEq)]
pub enum ChildOutcome {
    /// Exit status 0.
    Success {
        /// Wall-clock seconds.
        seconds: f64,
    },
    /// Anything else, with a one-line reason.
    Failure {
        /// Why, in one line.
        reason: String,
        /// Wall-clock seconds.
        seconds: f64,
    },
}

/// How often the guard looks at the child.
const POLL: Duration = Duration::from_millis(50);

/// Runs the child to its end, or kills it at its time or memory limit. Never panics: a child that
/// cannot even start is a failure like any other.
pub fn run_child(options: &ChildOptions) -> ChildOutcome {
    let started = Instant::now();
    let seconds = || started.elapsed().as_secs_f64();
    let failure = |reason: String| ChildOutcome::Failure {
        reason,
        seconds: seconds(),
    };
    let log = match std::fs::File::create(&options.log) {
        Ok(f) => f,
        Err(e) => return failure(format!("cannot create {}: {e}", options.log.display())),
    };
    let mut command = Command::new(&options.program);
    command
        .args(&options.args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(log);
    for (key, value) in &options.env {
        command.env(key, value);
    }
    let mut child = match command.spawn() {
        Ok(c) => c,
        Err(e) => return failure(format!("cannot start {}: {e}", options.program.display())),
    };
    let mut last_memory_check = Instant::now();
    let killed_because = loop {
        match child.try_wait() {
            Ok(Some(status)) => return ended(status, &options.log, seconds()),
            Ok(None) => {}
            Err(e) => break format!("cannot wait for the child: {e}"),
        }
        if let Some(limit) = options.timeout
            && started.elapsed() > limit
        {
            break format!("timed out after {} s", limit.as_secs_f64());
        }
        if let Some(limit) = options.max_memory
            && last_memory_check.elapsed() >= 4 * POLL
        {
            last_memory_check = Instant::now();
            if let Some(rss) = resident_bytes(child.id())
                && rss > limit
            {
                break format!(
                    "used {} MiB of memory, over --max-memory {} MiB",
                    rss >> 20,
                    limit >> 20
                );
            }
        }
        std::thread::sleep(POLL);
    };
    // A kill of a child that has just exited is harmless; the wait reaps it either way.
    let _ = child.kill();
    let _ = child.wait();
    failure(killed_because)
}

fn ended(status: ExitStatus, log: &Path, seconds: f64) -> ChildOutcome {
    if status.success() {
        return ChildOutcome::Success { seconds };
    }
    let reason = match status.code() {
        Some(code) => last_error_line(log).unwrap_or_else(|| format!("exit status {code}")),
        None => {
            use std::os::unix::process::ExitStatusExt;
            format!("killed by signal {}", status.signal().unwrap_or(0))
        }
    };
    ChildOutcome::Failure { reason, seconds }
}

/// The child's own one-line error (`roar: error: …`), else its last non-empty stderr line.
fn last_error_line(log: &Path) -> Option<String> {
    let text = std::fs::read_to_string(log).ok()?;
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    lines
        .iter()
        .rev()
        .find_map(|l| l.strip_prefix("roar: error: "))
        .or(lines.last().copied())
        .map(str::to_string)
}

/// The resident set size of a process in bytes, from `/proc/PID/status` (Linux); `None`
/// elsewhere or once the process is gone.
pub fn resident_bytes(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shell(script: &str, log: &Path) -> ChildOptions {
        ChildOptions {
            program: "/bin/sh".into(),
            args: vec!["-c".into(), script.into()],
            env: vec![("GREETING".into(), "hi".into())],
            timeout: Some(Duration::from_secs(5)),
            max_memory: None,
            log: log.to_path_buf(),
        }
    }

    #[test]
    fn outcomes_carry_one_line_reasons() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("log");
        let ok = run_child(&shell("test \"$GREETING\" = hi", &log));
        assert!(matches!(ok, ChildOutcome::Success { .. }), "{ok:?}");
        let failed = run_child(&shell(
            "echo note >&2; echo 'roar: error: x.obj: bad header' >&2; echo after >&2; exit 1",
            &log,
        ));
        assert!(
            matches!(&failed, ChildOutcome::Failure { reason, .. } if reason == "x.obj: bad header"),
            "{failed:?}"
        );
        let silent = run_child(&shell("exit 3", &log));
        assert!(
            matches!(&silent, ChildOutcome::Failure { reason, .. } if reason == "exit status 3")
        );
        let signalled = run_child(&shell("kill -9 $$", &log));
        assert!(
            matches!(&signalled, ChildOutcome::Failure { reason, .. } if reason == "killed by signal 9")
        );
        let missing = run_child(&ChildOptions {
            program: dir.path().join("nope"),
            ..shell("", &log)
        });
        assert!(
            matches!(&missing, ChildOutcome::Failure { reason, .. } if reason.starts_with("cannot start"))
        );
    }

    #[test]
    fn the_timeout_kills_the_child() {
        let dir = tempfile::tempdir().unwrap();
        let mut options = shell("sleep 30", &dir.path().join("log"));
        options.timeout = Some(Duration::from_millis(300));
        match run_child(&options) {
            ChildOutcome::Failure { reason, seconds } => {
                assert_eq!(reason, "timed out after 0.3 s");
                assert!(seconds < 10.0, "{seconds}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn the_memory_guard_kills_the_child() {
        let dir = tempfile::tempdir().unwrap();
        // The shell keeps the whole command substitution in its own memory.
        let mut options = shell(
            "x=$(head -c 200000000 /dev/zero | tr '\\0' a); sleep 30",
            &dir.path().join("log"),
        );
        options.max_memory = Some(64 << 20);
        options.timeout = Some(Duration::from_secs(60));
        match run_child(&options) {
            ChildOutcome::Failure { reason, .. } => {
                assert!(reason.contains("over --max-memory 64 MiB"), "{reason}")
            }
            other => panic!("{other:?}"),
        }
    }
}
