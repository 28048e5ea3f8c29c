//! Times the initial mesh (watertight init, then QEM to ≤ 20k faces) on the given mesh files, for
//! profiling: `cargo run --release -p roar-ops --example init_profile -- FILE...`.
//! `ROAR_MAX_FACES=N` changes the face cap (a large value skips the decimation). Prints the
//! stage times and a checksum of the result, to see whether a change kept the output identical.
//! For repeatable instruction counts:
//! `RAYON_NUM_THREADS=1 valgrind --tool=callgrind target/release/examples/init_profile FILE`.

mod common;

use roar_ops::init::{InitialMeshOptions, initial_mesh};
use std::path::Path;

fn main() {
    let max_faces = std::env::var("ROAR_MAX_FACES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    let options = InitialMeshOptions {
        max_faces,
        ..InitialMeshOptions::default()
    };
    for arg in std::env::args().skip(1) {
        let soup = roar_io::read_mesh(Path::new(&arg)).expect("readable mesh");
        let (mesh, stats) =
            initial_mesh(&soup.positions, &soup.triangles, &options).expect("initial mesh");
        println!(
            "{arg}: init {:.2}s ({} faces), build {:.2}s, decimate {:.2}s -> {} faces, checksum {:016x}",
            stats.init_seconds,
            stats.init_faces,
            stats.build_seconds,
            stats.decimate_seconds,
            stats.final_faces,
            common::mesh_checksum(&mesh)
        );
    }
}
