//! End-to-end reconstructions (release mode, run by `.ci/run` with `--ignored`): the shipped
//! example and two small wild meshes at 1000 faces. Each output must be a closed, oriented
//! 2-manifold with exactly the budget, no self-intersecting faces, no more components than the
//! init, and a Chamfer distance below that of the init decimated to the same budget (what the
//! optimization adds): at least 10 % below on trimesh-rabbit and luke-f-16, and not above it on
//! the example. Since the QEM has planar quadrics, the example's box-shaped init decimated to
//! 1000 faces is already about as close as roar gets (Chamfer/diag 2.40e-3 against roar's
//! 2.37e-3): what is left is the sheet's thickness and the soup's interior faces, which no
//! closed surface comes nearer to. On the two wild meshes the margin is larger
//! (trimesh-rabbit 2.87e-3 → 2.40e-3, luke-f-16 1.64e-3 → 1.40e-3).
//!
//! The inputs run side by side, one thread each: much of a run (the blocks, the step limiter,
//! the QEM) is sequential, so the second core would otherwise idle through it.

use std::path::PathBuf;

use roar::{ReconstructConfig, Reconstruction};
use roar_eval::{ChamferOptions, fidelity};
use roar_mesh::Mesh;
use roar_mesh::spatial::self_intersecting_faces;

const FACES: usize = 1000;

/// The inputs, each with the largest ratio of roar's Chamfer to the init + QEM's it must meet.
fn inputs() -> Vec<(PathBuf, f64)> {
    let mut files = vec![(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/chair_soup.obj"),
        1.0,
    )];
    match std::env::var_os("ROAR_TEST_DATA") {
        Some(root) => {
            let wild = PathBuf::from(root).join("wild");
            assert!(
                wild.is_dir(),
                "ROAR_TEST_DATA has no wild/ folder: {}",
                wild.display()
            );
            files.push((wild.join("trimesh-rabbit.obj"), 0.9));
            // Thin wings and fins: the Face Collapse block once ate them from their rims and
            // left this mesh 2.5× worse than its own init + QEM.
            files.push((wild.join("luke-f-16.obj"), 0.9));
        }
        None => assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "ROAR_TEST_DATA must be set under CI"
        ),
    }
    files
}

fn chamfer_over_diag(
    positions: &[glam::DVec3],
    triangles: &[[u32; 3]],
    soup: &roar_io::TriangleSoup,
) -> f64 {
    let options = ChamferOptions {
        samples: 100_000,
        seed: 7,
    };
    fidelity(
        positions,
        triangles,
        &soup.positions,
        &soup.triangles,
        &options,
    )
    .expect("both meshes have area")
    .chamfer_l2_over_diag
}

/// What one input gave: roar's output and the init + QEM baseline, both at `FACES`.
struct Run {
    out: roar::Output,
    baseline: roar::Output,
    seconds: f64,
}

fn reconstruct(name: &str, soup: &roar_io::TriangleSoup) -> Run {
    let config = ReconstructConfig {
        faces: FACES,
        ..ReconstructConfig::default()
    };
    let baseline_config = {
        let mut config = config.clone();
        config.optimize.iterations = 0;
        config
    };
    let baseline = Reconstruction::new(baseline_config)
        .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
        .unwrap_or_else(|e| panic!("{name}, init + QEM: {e}"));
    let started = std::time::Instant::now();
    let out = Reconstruction::new(config)
        .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    Run {
        out,
        baseline,
        seconds: started.elapsed().as_secs_f64(),
    }
}

#[test]
#[ignore = "minutes in release; run by .ci/run"]
fn reconstruction_beats_init_plus_qem_and_keeps_every_promise() {
    let inputs: Vec<(String, roar_io::TriangleSoup, f64)> = inputs()
        .into_iter()
        .map(|(path, wanted)| {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            (name, roar_io::read_mesh(&path).unwrap(), wanted)
        })
        .collect();
    let runs: Vec<Run> = std::thread::scope(|scope| {
        let handles: Vec<_> = inputs
            .iter()
            .map(|(name, soup, _)| scope.spawn(move || reconstruct(name, soup)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });

    for ((name, soup, wanted), run) in inputs.iter().zip(runs) {
        let (out, baseline) = (&run.out, &run.baseline);
        assert_eq!(out.triangles.len(), FACES, "{name}: exact budget");
        let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles)
            .unwrap_or_else(|e| panic!("{name}: not a closed manifold: {e}"));
        mesh.validate().unwrap();
        assert!(mesh.signed_volume() > 0.0, "{name}: outward orientation");
        assert!(
            mesh.components().0 <= out.stats.init.init_components,
            "{name}: more components than the init"
        );
        let crossing = self_intersecting_faces(&out.positions, &out.triangles)
            .iter()
            .filter(|&&x| x)
            .count();
        assert_eq!(crossing, 0, "{name}: self-intersecting faces");

        let ours = chamfer_over_diag(&out.positions, &out.triangles, soup);
        let init = chamfer_over_diag(&baseline.positions, &baseline.triangles, soup);
        eprintln!(
            "{name}: chamfer/diag {ours:.5} vs init+QEM {init:.5} ({:+.1} %), {:.1} s",
            100.0 * (ours / init - 1.0),
            run.seconds
        );
        assert!(
            ours <= wanted * init,
            "{name}: chamfer/diag {ours} is not {:.0} % below init + QEM {init}",
            100.0 * (1.0 - wanted)
        );
    }
}

/// trimesh-soup.stl (random triangles) without the enclosure rule (its init has genus 89) at 500
/// faces: the finish must remove handles to reach the budget, and no cut may leave a crossing in
/// the output (at this budget the untangle clears the cuts' crossings only once more handles are
/// removed first). With the rule, the box's middle fills and the init has genus 20.
#[test]
#[ignore = "minutes in release; run by .ci/run"]
fn a_soup_of_random_triangles_meets_the_budget_by_removing_handles_without_crossings() {
    let Some(root) = std::env::var_os("ROAR_TEST_DATA") else {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "ROAR_TEST_DATA must be set under CI"
        );
        return;
    };
    let soup = roar_io::read_mesh(&PathBuf::from(root).join("wild/trimesh-soup.stl")).unwrap();
    let faces = 500;
    let mut config = ReconstructConfig {
        faces,
        ..ReconstructConfig::default()
    };
    config.init.enclosure_winding_threshold = 0.0;
    let out = Reconstruction::new(config)
        .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
        .unwrap_or_else(|e| panic!("trimesh-soup: {e}"));
    assert!(!out.stats.finish.handles_removed.is_empty());
    assert_eq!(out.triangles.len(), faces);
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles).unwrap();
    mesh.validate().unwrap();
    let crossing = self_intersecting_faces(&out.positions, &out.triangles);
    assert_eq!(crossing.iter().filter(|&&x| x).count(), 0);
}
