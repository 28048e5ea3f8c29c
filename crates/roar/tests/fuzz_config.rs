//! A mutation fuzzer for the configuration parser: the default configuration's TOML text and a
//! few hand-written overrides, mutated and parsed as `roar reconstruct --config` does, then
//! validated. Nothing may panic; whatever parses either validates or is refused in one line.
//! `scripts/fuzz.sh` runs 1 M executions in release mode, `cargo test` a smoke run.

#[path = "../../roar-io/tests/fuzz/mutate.rs"]
mod mutate;

use std::panic::{AssertUnwindSafe, catch_unwind};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar::ReconstructConfig;

#[test]
fn the_config_parser_survives_mutated_seeds() {
    let executions = mutate::executions(2_000);
    let seeds: Vec<Vec<u8>> = [
        toml::to_string(&ReconstructConfig::default()).unwrap(),
        "faces = 1000\n[optimize]\niterations = 20\n[init]\nkind = \"sphere\"\n".to_string(),
        "[loss]\nrender_weight = 3.0\nplanar_weight = 1e-3\n[finish]\nsliver_quality = 0\n"
            .to_string(),
        "seed = 18446744073709551615\n[optimize]\nworking_budget_min = 100\nworking_budget_max = 200\n"
            .to_string(),
        // The ungrouped layout, refused with the table each key belongs in.
        "iterations = 20\nrender_weight = 3.0\ninit = \"sphere\"\n".to_string(),
    ]
    .into_iter()
    .map(String::into_bytes)
    .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(
        std::env::var("ROAR_FUZZ_SEED")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1),
    );
    let (mut valid, mut refused_by_range, mut refused_by_parser) = (0usize, 0usize, 0usize);
    for run in 0..executions {
        let mut bytes = seeds[rng.random_range(0..seeds.len())].clone();
        mutate::mutate(&mut rng, &mut bytes, &seeds);
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let text = String::from_utf8_lossy(&bytes);
            ReconstructConfig::from_toml(&text, &ReconstructConfig::default()).map(|c| c.validate())
        }));
        match outcome {
            Ok(Ok(Ok(()))) => valid += 1,
            Ok(Ok(Err(error))) => {
                let message = error.to_string();
                assert_eq!(message.lines().count(), 1, "{message}");
                refused_by_range += 1;
            }
            Ok(Err(_)) => refused_by_parser += 1,
            Err(_) => {
                let path = mutate::save_crash(&format!("config-{run}"), &bytes);
                panic!(
                    "the config parser panicked; input kept at {}",
                    path.display()
                );
            }
        }
    }
    eprintln!(
        "fuzz config: {executions} executions, {valid} valid, {refused_by_range} refused by a \
         range, {refused_by_parser} refused by the parser, 0 panics"
    );
}
