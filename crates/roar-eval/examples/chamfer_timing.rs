//! Times `evaluate` with the default 200k samples per side on a real mesh against itself
//! (or a procedural sphere pair): `cargo run --release -p roar-eval --example chamfer_timing [FILE.obj]`.

use std::time::Instant;

use glam::DVec3;
use roar_eval::{ChamferOptions, EvalOptions, evaluate, fidelity, topology};

/// CPU seconds used by the whole process so far (all threads; Linux `/proc/self/stat`, 100 Hz ticks).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map(|x| x.1).unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    if f.len() > 13 {
        (f[11] + f[12]) / 100.0
    } else {
        f64::NAN
    }
}

fn main() {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        std::env::var("ROAR_TEST_DATA").expect("give a file or set ROAR_TEST_DATA")
            + "/clean/armadillo.obj"
    });
    let soup = roar_io::read_mesh(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let (p, t) = (soup.positions, soup.triangles);
    let shifted: Vec<DVec3> = p.iter().map(|q| *q * 1.01).collect();
    println!(
        "{path}: {} vertices, {} faces, threads {}",
        p.len(),
        t.len(),
        rayon::current_num_threads()
    );
    breakdown(&p, &t);
    let opts = ChamferOptions::default();
    for run in 0..3 {
        let start = Instant::now();
        let cpu = cpu_seconds();
        let f = fidelity(&shifted, &t, &p, &t, &opts).unwrap();
        println!(
            "run {run}: fidelity (2 x {} samples) wall {:.3} s, cpu {:.2} s; chamfer/diag {:.3e}, cos {:.4}",
            opts.samples,
            start.elapsed().as_secs_f64(),
            cpu_seconds() - cpu,
            f.chamfer_l2_over_diag,
            f.normal_cosine
        );
    }
    let start = Instant::now();
    let topo = topology(&p, &t);
    println!(
        "topology {:.3} s (components {})",
        start.elapsed().as_secs_f64(),
        topo.components
    );
    let start = Instant::now();
    let report = evaluate(&shifted, &t, Some((&p, &t)), &EvalOptions::default()).unwrap();
    println!(
        "evaluate (all) {:.3} s; watertight {}",
        start.elapsed().as_secs_f64(),
        report.topology_welded.watertight
    );
}

/// Stage breakdown of one fidelity call.
#[allow(dead_code)]
pub fn breakdown(p: &[DVec3], t: &[[u32; 3]]) {
    let start = Instant::now();
    let a = roar_mesh::spatial::sample_surface(p, t, 200_000, 0);
    let b = roar_mesh::spatial::sample_surface(p, t, 200_000, 1);
    println!(
        "  sampling 2 x 200k: {:.3} s",
        start.elapsed().as_secs_f64()
    );
    let start = Instant::now();
    let n = roar_eval::nearest_neighbours(&a.points, &b.points);
    println!(
        "  one tree + 200k queries: {:.3} s ({})",
        start.elapsed().as_secs_f64(),
        n.len()
    );
    let start = Instant::now();
    let n = roar_eval::nearest_neighbours(&a.points, &b.points[..1]);
    println!(
        "  one tree + 1 query: {:.3} s ({})",
        start.elapsed().as_secs_f64(),
        n.len()
    );
}
