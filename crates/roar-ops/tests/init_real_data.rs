//! The watertight init on the shared real meshes (`$ROAR_TEST_DATA/{clean,wild}`): every output is
//! a closed, outward-oriented 2-manifold close to the soup. Prints per-mesh time, faces and the
//! mean distances (output → soup and soup → output, over the bounding-box diagonal).

mod common;

use common::{check_closed_manifold, data_dir};
use glam::DVec3;
use roar_mesh::spatial::TriangleBvh;
use roar_ops::init::{InitOptions, watertight_init};
use std::path::{Path, PathBuf};
use std::time::Instant;

fn mean_distance(grid: &TriangleBvh, points: &[DVec3]) -> f64 {
    points
        .iter()
        .map(|p| grid.closest_point(*p).unwrap().distance_squared.sqrt())
        .sum::<f64>()
        / points.len() as f64
}

/// Runs the init on one file, checks it, prints a row and returns the output → soup distance / diag.
fn check_file(path: &Path) -> f64 {
    let soup = roar_io::read_mesh(path).unwrap_or_else(|e| panic!("{e}"));
    let start = Instant::now();
    let out = watertight_init(&soup.positions, &soup.triangles, &InitOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let seconds = start.elapsed().as_secs_f64();
    let report = check_closed_manifold(&out.positions, &out.triangles)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let used: Vec<DVec3> = soup
        .triangles
        .iter()
        .flatten()
        .map(|&i| soup.positions[i as usize])
        .collect();
    let (min, max) = used
        .iter()
        .fold((used[0], used[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let diag = (max - min).length();
    let soup_grid = TriangleBvh::build(&soup.positions, &soup.triangles);
    let out_grid = TriangleBvh::build(&out.positions, &out.triangles);
    let forward = mean_distance(&soup_grid, &out.positions) / diag;
    let backward = mean_distance(&out_grid, &used) / diag;
    println!(
        "{:<40} {:>7.2}s {:>8} faces {:>3} pieces (dropped {:>3}) genus-sum χ={:>4}  out→soup {:.5}  soup→out {:.5}  chamfer {:.5}",
        path.file_name().unwrap().to_string_lossy(),
        seconds,
        report.faces,
        out.stats.pieces,
        out.stats.dropped_pieces,
        report.euler,
        forward,
        backward,
        0.5 * (forward + backward),
    );
    assert!(forward < 0.01, "{}: out→soup {forward}", path.display());
    forward
}

#[test]
fn small_wild_meshes_become_closed_manifolds_near_the_soup() {
    let Some(dir) = data_dir() else { return };
    for name in [
        "gc-moebius.obj",
        "gc-hourglass_ico.obj",
        "cgal-non_manifold_face_graph.off",
    ] {
        check_file(&dir.join("wild").join(name));
    }
}

/// Every shared mesh; slow in the dev profile, run in release:
/// `cargo test --release -p roar-ops --test init_real_data -- --ignored --nocapture`.
#[test]
#[ignore]
fn every_shared_mesh_becomes_a_closed_manifold_near_the_soup() {
    let Some(dir) = data_dir() else { return };
    for folder in ["clean", "wild"] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join(folder))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for file in files {
            check_file(&file);
        }
    }
}
