//! Times QEM decimation on a large closed mesh, for profiling:
//! `cargo run --release -p roar-ops --example qem_profile -- [SOURCE] [FIRST] [SECOND]`.
//!
//! `SOURCE` is a mesh file (its watertight init is decimated; the init is cached under the
//! system temp dir, keyed by the file name) or `torus` (a 200k-face torus, the default).
//! The mesh is decimated to `FIRST` faces (default 20 000), then to `SECOND` (default 5 000).
//! Prints the time, stats and a checksum of the result (to see whether a change kept the
//! output identical). With `QEM_PARALLEL=1` set, [`decimate_in_parallel`] is timed instead (as
//! `roar init` runs it; the cpu figure is then only the calling thread's).

mod common;

use roar_mesh::Mesh;
use roar_mesh::shapes::{perturbed, torus};
use roar_ops::decimate::{DecimateOptions, decimate, decimate_in_parallel};
use roar_ops::init::{InitOptions, watertight_init};
use std::path::{Path, PathBuf};
use std::time::Instant;

fn cache_path(file: &str) -> PathBuf {
    let name = Path::new(file)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    std::env::temp_dir().join(format!("qem_profile_{name}.bin"))
}

fn load_init(file: &str) -> Mesh {
    let cache = cache_path(file);
    if let Ok(bytes) = std::fs::read(&cache) {
        let nv = u64::from_le_bytes(bytes[0..8].try_into().unwrap()) as usize;
        let f64s = |i: usize| f64::from_le_bytes(bytes[8 + 8 * i..16 + 8 * i].try_into().unwrap());
        let positions: Vec<glam::DVec3> = (0..nv)
            .map(|i| glam::DVec3::new(f64s(3 * i), f64s(3 * i + 1), f64s(3 * i + 2)))
            .collect();
        let rest = &bytes[8 + 24 * nv..];
        let tris: Vec<[u32; 3]> = rest
            .chunks_exact(12)
            .map(|c| [0, 1, 2].map(|k| u32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap())))
            .collect();
        return Mesh::from_triangles(positions, &tris).expect("cached init is a closed mesh");
    }
    let soup = roar_io::read_mesh(Path::new(file)).expect("readable mesh");
    let start = Instant::now();
    let init = watertight_init(&soup.positions, &soup.triangles, &InitOptions::default())
        .expect("watertight init");
    println!("watertight init: {:.2?}", start.elapsed());
    let mut bytes = (init.positions.len() as u64).to_le_bytes().to_vec();
    for p in &init.positions {
        for x in [p.x, p.y, p.z] {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
    }
    for t in &init.triangles {
        for i in t {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    std::fs::write(&cache, bytes).expect("cache written");
    Mesh::from_triangles(init.positions, &init.triangles).expect("init is a closed mesh")
}

/// CPU time of this thread in seconds (Linux `/proc/thread-self/schedstat`; 0 elsewhere): on a
/// loaded machine it is a steadier measure than wall time.
fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let source = args.first().map(String::as_str).unwrap_or("torus");
    let first: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let second: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5_000);
    let parallel = std::env::var_os("QEM_PARALLEL").is_some();
    let mut mesh = if source == "torus" {
        perturbed(&torus(400, 250, 1.0, 0.35), 0.002, 7)
    } else {
        load_init(source)
    };
    let options = DecimateOptions {
        best_effort: true,
        ..DecimateOptions::default()
    };
    for target in [first, second] {
        let before = mesh.n_faces();
        let start = Instant::now();
        let cpu = cpu_seconds();
        let stats = if parallel {
            decimate_in_parallel(&mut mesh, target, &options)
        } else {
            decimate(&mut mesh, target, &options)
        }
        .expect("decimate");
        println!(
            "{source}: {before} -> {} faces in {:.3?} wall, {:.3}s cpu (passes {}, bound {:?}, vetoes: {}) checksum {:016x}",
            stats.final_faces,
            start.elapsed(),
            cpu_seconds() - cpu,
            stats.passes,
            stats.quality_bound,
            stats.vetoes,
            common::mesh_checksum(&mesh)
        );
    }
}
