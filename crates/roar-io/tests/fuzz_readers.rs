//! A mutation fuzzer for every reader (OBJ, PLY, STL, OFF): seeds are the hand-made valid files
//! and, when `ROAR_TEST_DATA` is set, the shared meshes cut to at most 64 KB at run time (they
//! are third-party files and never committed). Each execution mutates a seed and feeds it to the
//! reader of its format: no input may panic, an accepted soup must be valid, an error must be one
//! line naming the file. Not coverage-guided (no fuzzer that runs on the stable toolchain was
//! available); `scripts/fuzz.sh` runs 1 M executions per reader in release mode, `cargo test`
//! a smoke run of a few thousand.

mod common;
#[path = "fuzz/mutate.rs"]
mod mutate;

use std::panic::{AssertUnwindSafe, catch_unwind};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_io::{MeshFormat, read_mesh_bytes};

const SEED_BYTES: usize = 64 * 1024;

/// Seeds per format: the hand-made files, then the shared meshes (first 64 KB of the big ones).
fn seeds() -> Vec<(MeshFormat, Vec<u8>)> {
    let mut seeds: Vec<(MeshFormat, Vec<u8>)> = common::valid_files()
        .into_iter()
        .map(|(name, bytes)| (MeshFormat::from_path(name.as_ref()).unwrap(), bytes))
        .collect();
    if let Some(root) = std::env::var_os("ROAR_TEST_DATA") {
        for folder in ["clean", "wild"] {
            let dir = std::path::Path::new(&root).join(folder);
            let mut files: Vec<_> = std::fs::read_dir(&dir)
                .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
                .map(|e| e.unwrap().path())
                .collect();
            files.sort();
            for path in files {
                let Ok(format) = MeshFormat::from_path(&path) else {
                    continue;
                };
                let mut bytes = std::fs::read(&path).unwrap();
                bytes.truncate(SEED_BYTES);
                seeds.push((format, bytes));
            }
        }
    }
    seeds
}

#[test]
fn every_reader_survives_mutated_seeds() {
    let executions = mutate::executions(2_000);
    let seeds = seeds();
    let donors: Vec<Vec<u8>> = seeds.iter().map(|(_, b)| b.clone()).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(
        std::env::var("ROAR_FUZZ_SEED")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1),
    );
    for format in [
        MeshFormat::Obj,
        MeshFormat::Ply,
        MeshFormat::Stl,
        MeshFormat::Off,
    ] {
        let own: Vec<&Vec<u8>> = seeds
            .iter()
            .filter(|(f, _)| *f == format)
            .map(|(_, b)| b)
            .collect();
        let (mut accepted, mut refused) = (0usize, 0usize);
        for run in 0..executions {
            let mut bytes = own[rng.random_range(0..own.len())].clone();
            mutate::mutate(&mut rng, &mut bytes, &donors);
            match catch_unwind(AssertUnwindSafe(|| read_mesh_bytes(&bytes, "fuzz", format))) {
                Ok(Ok(soup)) => {
                    assert_eq!(
                        soup.validate(),
                        Ok(()),
                        "{format:?} accepted an invalid soup"
                    );
                    accepted += 1;
                }
                Ok(Err(e)) => {
                    let message = e.to_string();
                    assert!(message.starts_with("fuzz"), "{message}");
                    assert!(!message.contains('\n'), "{message}");
                    refused += 1;
                }
                Err(_) => {
                    let path = mutate::save_crash(&format!("{format:?}-{run}"), &bytes);
                    panic!(
                        "{format:?} reader panicked; input kept at {}",
                        path.display()
                    );
                }
            }
        }
        eprintln!(
            "fuzz {format:?}: {executions} executions from {} seeds, {accepted} accepted, \
             {refused} refused, 0 panics",
            own.len()
        );
    }
}
