//! Times `fidelity` and `evaluate` on a real mesh against a copy scaled by 1.01, and splits the
//! fidelity time into its sampled (k-d tree) and exact (BVH closest point) passes:
//! `cargo run --release -p roar-eval --example chamfer_timing [FILE.obj [SAMPLES]]` (default: the
//! armadillo of `$ROAR_TEST_DATA`, `ChamferOptions::default().samples`).

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
    let samples = std::env::args()
        .nth(2)
        .map(|n| n.parse().expect("SAMPLES is a count"))
        .unwrap_or(ChamferOptions::default().samples);
    let (p, t) = (soup.positions, soup.triangles);
    let shifted: Vec<DVec3> = p.iter().map(|q| *q * 1.01).collect();
    println!(
        "{path}: {} vertices, {} faces, threads {}",
        p.len(),
        t.len(),
        rayon::current_num_threads()
    );
    breakdown(&shifted, &p, &t, samples);
    let opts = ChamferOptions {
        samples,
        ..ChamferOptions::default()
    };
    for run in 0..3 {
        let start = Instant::now();
        let cpu = cpu_seconds();
        let f = fidelity(&shifted, &t, &p, &t, &opts).unwrap();
        println!(
            "run {run}: fidelity (2 x {} samples) wall {:.3} s, cpu {:.2} s; chamfer/diag {:.3e} \
             (exact {:.3e}), cos {:.4} (exact {:.4})",
            opts.samples,
            start.elapsed().as_secs_f64(),
            cpu_seconds() - cpu,
            f.chamfer_l2_over_diag,
            f.chamfer_exact_over_diag,
            f.normal_cosine,
            f.normal_cosine_exact
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
    let eval_options = EvalOptions {
        chamfer: opts,
        ..EvalOptions::default()
    };
    let report = evaluate(&shifted, &t, Some((&p, &t)), &eval_options).unwrap();
    println!(
        "evaluate (all) {:.3} s; watertight {}",
        start.elapsed().as_secs_f64(),
        report.topology_welded.watertight
    );
}

/// Stage breakdown of one fidelity call of `shifted` against `p` (same triangles), wall and CPU
/// seconds: sampling, the sampled passes (two k-d trees, one query per sample), and the whole
/// call; the exact passes (two BVHs, one closest-point search per sample) are the rest.
pub fn breakdown(shifted: &[DVec3], p: &[DVec3], t: &[[u32; 3]], samples: usize) {
    let clock = || (Instant::now(), cpu_seconds());
    let since = |(wall, cpu): (Instant, f64)| (wall.elapsed().as_secs_f64(), cpu_seconds() - cpu);
    let start = clock();
    let (a, b) = rayon::join(
        || roar_mesh::spatial::sample_surface(shifted, t, samples, 0),
        || roar_mesh::spatial::sample_surface(p, t, samples, 1),
    );
    let sampling = since(start);
    let start = clock();
    let (ab, ba) = rayon::join(
        || roar_eval::nearest_neighbours(&b.points, &a.points),
        || roar_eval::nearest_neighbours(&a.points, &b.points),
    );
    let sampled = since(start);
    assert_eq!(ab.len() + ba.len(), 2 * samples);
    let options = ChamferOptions {
        samples,
        ..ChamferOptions::default()
    };
    let start = clock();
    fidelity(shifted, t, p, t, &options).expect("the mesh has area");
    let whole = since(start);
    println!(
        "  2 x {samples} samples, wall / cpu s: sampling {:.3} / {:.2}, sampled passes {:.3} / {:.2}, \
         whole fidelity {:.3} / {:.2}, so exact passes ≈ {:.3} / {:.2}",
        sampling.0,
        sampling.1,
        sampled.0,
        sampled.1,
        whole.0,
        whole.1,
        whole.0 - sampling.0 - sampled.0,
        whole.1 - sampling.1 - sampled.1
    );
}
