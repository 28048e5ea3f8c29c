//! build_target and the point cloud on real wild soups from `$ROAR_TEST_DATA/wild`.
//! Slow at the paper's 512² (a few seconds per mesh in release): run with `--ignored`.

mod common;

use std::time::Instant;

use roar_loss::{PointCloudOptions, TargetOptions, build_target, point_cloud};
use roar_mesh::spatial::RIG_RADIUS;

#[test]
#[ignore = "real meshes at 512², several seconds each; run with --ignored (release)"]
fn wild_soups_give_clean_targets_and_point_clouds() {
    let Some(dir) = common::wild_dir() else {
        return;
    };
    for name in [
        "trimesh-chair_model.obj",
        "manifoldplus-chair.off",
        "trimesh-rabbit.obj",
    ] {
        let soup = roar_io::read_mesh(&dir.join(name)).unwrap_or_else(|e| panic!("{e}"));
        let (positions, triangles) = (soup.positions, soup.triangles);
        let (start, cpu) = (Instant::now(), common::cpu_seconds());
        let target = build_target(&positions, &triangles, &TargetOptions::default()).unwrap();
        let build_time = start.elapsed();
        let build_cpu = common::cpu_seconds() - cpu;
        let (start, cpu) = (Instant::now(), common::cpu_seconds());
        let cloud = point_cloud(&target, &PointCloudOptions::default()).unwrap();
        let cloud_time = start.elapsed();
        let cloud_cpu = common::cpu_seconds() - cpu;
        let s = target.stats;
        println!(
            "{name}: {} v / {} f in; welded {}, degenerate {}, duplicates {}, twins dropped {}, \
             undecided {}, tied {} (unseen {}), unreferenced {}; T' {} v / {} f; \
             build_target {:.2} s ({:.2} s CPU); P {} of 200k in {:.2} s ({:.2} s CPU)",
            s.input_vertices,
            s.input_faces,
            s.welded_vertices,
            s.degenerate_faces_removed,
            s.duplicate_faces_removed,
            s.twins_dropped,
            s.pairs_undecided,
            s.pairs_tied,
            s.pairs_unseen,
            s.unreferenced_vertices_dropped,
            s.output_vertices,
            s.output_faces,
            build_time.as_secs_f64(),
            build_cpu,
            cloud.len(),
            cloud_time.as_secs_f64(),
            cloud_cpu,
        );
        let pairs = s.twins_dropped + s.pairs_undecided + s.pairs_tied;
        assert_eq!(
            s.output_faces,
            2 * pairs - s.twins_dropped,
            "every pair keeps one or two faces"
        );
        assert_eq!(
            pairs + s.duplicate_faces_removed + s.degenerate_faces_removed,
            s.input_faces
        );
        // Faces under 80 visible pixels can never be decided (hi/(lo+1) ≥ 80 needs hi ≥ 80),
        // so on finely tessellated soups many pairs stay undecided; some must be decided.
        assert!(s.twins_dropped > 0, "{s:?}");
        let r = target
            .positions
            .iter()
            .map(|p| p.length())
            .fold(0.0, f64::max);
        assert!((r - RIG_RADIUS).abs() < 1e-9);
        assert!(
            cloud.len() > 100_000,
            "P keeps most samples: {}",
            cloud.len()
        );
        assert!(
            cloud
                .normals
                .iter()
                .all(|n| (n.length() - 1.0).abs() < 1e-9)
        );
    }
}
