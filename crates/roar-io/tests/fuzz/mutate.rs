//! The byte mutator of the fuzz harnesses (`fuzz_readers.rs` here, `fuzz_config.rs` in
//! roar-cli): random edits of a seed, biased towards what parsers trip on (numbers at their
//! limits, NaN and infinities, separators, truncations, chunks of other seeds).
#![allow(dead_code)]

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Tokens that stress number parsing and counts.
const TOKENS: &[&[u8]] = &[
    b"nan",
    b"-nan",
    b"inf",
    b"-inf",
    b"1e309",
    b"-1",
    b"0",
    b"-0",
    b"4294967295",
    b"4294967296",
    b"18446744073709551615",
    b"99999999999999999999",
    b"1e-320",
    b"0x10",
    b"+",
    b"-",
    b".",
    b"",
    b"\n",
    b"\r\n",
    b" ",
    b"\t",
    b"#",
    b"/",
    b"//",
    b"\"",
    b"[",
    b"]",
    b"=",
    b"\0",
    b"\xff",
];

/// Applies 1 to 3 random edits (one in half the cases) to `bytes`; `donors` supplies chunks of other inputs.
pub fn mutate(rng: &mut ChaCha8Rng, bytes: &mut Vec<u8>, donors: &[Vec<u8>]) {
    let edits = if rng.random_bool(0.5) {
        1
    } else {
        rng.random_range(2..=3)
    };
    for _ in 0..edits {
        let n = bytes.len();
        let at = if n == 0 { 0 } else { rng.random_range(0..n) };
        match rng.random_range(0..8) {
            0 if n > 0 => bytes[at] ^= 1 << rng.random_range(0..8),
            1 if n > 0 => bytes[at] = rng.random(),
            2 => {
                let len = rng.random_range(1..64).min(n - at);
                bytes.drain(at..at + len);
            }
            3 => {
                let token = TOKENS[rng.random_range(0..TOKENS.len())];
                bytes.splice(at..at, token.iter().copied());
            }
            4 => {
                // Replace the number (or word) at `at` by a token.
                let end = (at..n)
                    .find(|&i| bytes[i].is_ascii_whitespace())
                    .unwrap_or(n);
                let token = TOKENS[rng.random_range(0..TOKENS.len())];
                bytes.splice(at..end, token.iter().copied());
            }
            5 => bytes.truncate(at),
            6 if n > 0 => {
                // Duplicate a chunk of the input elsewhere.
                let start = rng.random_range(0..n);
                let len = rng.random_range(1..256).min(n - start);
                let chunk: Vec<u8> = bytes[start..start + len].to_vec();
                let to = rng.random_range(0..=n);
                bytes.splice(to..to, chunk);
            }
            _ if !donors.is_empty() => {
                let donor = &donors[rng.random_range(0..donors.len())];
                if !donor.is_empty() {
                    let start = rng.random_range(0..donor.len());
                    let len = rng.random_range(1..512).min(donor.len() - start);
                    bytes.splice(at..at, donor[start..start + len].iter().copied());
                }
            }
            _ => {}
        }
    }
}

/// How many executions a harness runs: `ROAR_FUZZ_EXECS`, or `default` (the smoke run).
pub fn executions(default: usize) -> usize {
    std::env::var("ROAR_FUZZ_EXECS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Keeps an input that made a parser panic, for the report, and returns where.
pub fn save_crash(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz-crashes");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}
