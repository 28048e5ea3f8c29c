//! Times the watertight init on the given mesh files (for profiling with callgrind):
//! `cargo run --release -p roar-ops --example init_profile -- FILE...`.

use roar_ops::init::{InitOptions, watertight_init};
use std::path::Path;
use std::time::Instant;

fn main() {
    for arg in std::env::args().skip(1) {
        let soup = roar_io::read_mesh(Path::new(&arg)).expect("readable mesh");
        let start = Instant::now();
        let out = watertight_init(&soup.positions, &soup.triangles, &InitOptions::default())
            .expect("init succeeds");
        println!(
            "{arg}: {:.2}s, {} input faces -> {} faces",
            start.elapsed().as_secs_f64(),
            soup.triangles.len(),
            out.triangles.len()
        );
    }
}
