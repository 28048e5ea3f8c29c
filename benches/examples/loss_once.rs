//! One evaluation of the loop's objective (value and gradient, default rig) on the loss bench's
//! source, for instruction counts that repeat on a loaded machine:
//!
//! ```sh
//! ROAR_TEST_DATA=… RAYON_NUM_THREADS=1 valgrind --tool=callgrind \
//!     --toggle-collect='*value_and_grad*' target/release/examples/loss_once [FACES] [PART]
//! ```
//!
//! FACES defaults to 10,000; PART is `full` (default), `render` (forward + backward) or
//! `planar`. The source is `clean/homer.obj` decimated to FACES and shrunk by 2 %, as in
//! `benches/loss.rs`.

use glam::DVec3;
use roar_cli::pipeline::{
    Prepared, ReconstructConfig, default_loss, planar_options, target_options,
};
use roar_loss::{Loss, PlanarLoss, PointCloudOptions, RenderLoss, build_target, point_cloud};
use roar_mesh::Mesh;
use roar_ops::decimate::{DecimateOptions, decimate};

fn main() {
    let mut args = std::env::args().skip(1);
    let faces: usize = args.next().map_or(10_000, |a| a.parse().expect("FACES"));
    let part = args.next().unwrap_or_else(|| "full".into());
    let dir = std::env::var_os("ROAR_TEST_DATA").expect("set ROAR_TEST_DATA");
    let soup = roar_io::read_mesh(&std::path::Path::new(&dir).join("clean/homer.obj")).unwrap();
    let config = ReconstructConfig::default();
    let target = build_target(&soup.positions, &soup.triangles, &target_options(&config)).unwrap();
    let cloud = point_cloud(&target, &PointCloudOptions::default()).unwrap();
    let mut normalized = soup.positions.clone();
    target.normalization.apply_all(&mut normalized);
    let mut mesh = Mesh::from_triangles(normalized, &soup.triangles).unwrap();
    decimate(&mut mesh, faces, &DecimateOptions::default()).unwrap();
    let (positions, triangles) = mesh.to_triangles();
    let positions: Vec<DVec3> = positions.iter().map(|p| *p * 0.98).collect();
    let prepared = Prepared {
        cameras: &target.cameras,
        renders: &target.renders,
        cloud: &cloud,
        signed_distance: None,
        config: &config,
    };
    let value = match part.as_str() {
        "full" => default_loss(&prepared)
            .unwrap()
            .value_and_grad(&positions, &triangles),
        "render" => RenderLoss::new(&target).value_and_grad(&positions, &triangles),
        "planar" => PlanarLoss::new(&cloud.points, &cloud.normals, &planar_options(&config))
            .unwrap()
            .value_and_grad(&positions, &triangles),
        other => panic!("PART is full, render or planar, not {other}"),
    }
    .unwrap()
    .0;
    println!("{part} loss at {} faces: {value}", triangles.len());
}
