//! Gradient balance of the objective's terms on a real mesh and its init, which chose
//! the pipeline's `planar_scale` (`docs/method.md#decision-balance-of-the-planar-term`):
//! mean per-vertex gradient norm of λ1·render, of the planar term (raw and at its default scale),
//! and of the optimizer's Laplacian term `w_lap·ν·δ_v` (with ν = 1, its value after a first step).
//!
//! `cargo run --release -p roar --example loss_balance -- MESH [FACES]`

use glam::DVec3;
use roar::ReconstructConfig;
use roar_loss::{
    Loss, PlanarLoss, PlanarOptions, PointCloudOptions, RenderLoss, TargetOptions, build_target,
    point_cloud,
};
use roar_ops::decimate::{DecimateOptions, decimate};
use roar_ops::init::{InitialMeshOptions, initial_mesh};

/// Any error, as one line for the terminal.
type Result<T, E = Box<dyn std::error::Error>> = std::result::Result<T, E>;

fn mean_norm(g: &[DVec3]) -> f64 {
    g.iter().map(|v| v.length()).sum::<f64>() / g.len() as f64
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("usage: loss_balance MESH [FACES]");
    let faces: usize = args.get(2).map_or(Ok(5000), |f| f.parse())?;
    let config = ReconstructConfig::default();
    let soup = roar_io::read_mesh(std::path::Path::new(path))?;
    let target = build_target(&soup.positions, &soup.triangles, &TargetOptions::default())?;
    let (mut mesh, _) = initial_mesh(
        &target.positions,
        &target.triangles,
        &InitialMeshOptions::default(),
    )?;
    if mesh.n_faces() > faces {
        decimate(
            &mut mesh,
            faces,
            &DecimateOptions {
                best_effort: true,
                ..DecimateOptions::default()
            },
        )?;
    }
    let (positions, triangles) = mesh.to_triangles();
    let cloud = point_cloud(&target, &PointCloudOptions::default())?;

    let (_, render) = RenderLoss::new(&target).value_and_grad(&positions, &triangles)?;
    let render: Vec<DVec3> = render
        .iter()
        .map(|g| config.loss.render_weight * *g)
        .collect();
    let mut raw = PlanarLoss::new(&cloud.points, &cloud.normals, &PlanarOptions::raw())?;
    let (_, planar_raw) = raw.value_and_grad(&positions, &triangles)?;
    let mut scaled = PlanarLoss::new(&cloud.points, &cloud.normals, &PlanarOptions::default())?;
    let (_, planar) = scaled.value_and_grad(&positions, &triangles)?;

    // δ_v = v − mean of its neighbours.
    let mut sum = vec![DVec3::ZERO; positions.len()];
    let mut count = vec![0usize; positions.len()];
    for t in &triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            sum[a] += positions[b];
            count[a] += 1;
        }
    }
    let laplacian: Vec<DVec3> = (0..positions.len())
        .map(|v| config.optimize.laplacian_weight * (positions[v] - sum[v] / count[v] as f64))
        .collect();

    println!(
        "{path}: {} faces, {} target points",
        triangles.len(),
        cloud.points.len()
    );
    println!("mean |grad| per vertex:");
    println!(
        "  render × {}      {:.3e}",
        config.loss.render_weight,
        mean_norm(&render)
    );
    println!("  planar raw × 1      {:.3e}", mean_norm(&planar_raw));
    println!(
        "  planar default × 1  {:.3e}  (scale {})",
        mean_norm(&planar),
        PlanarOptions::default().scale
    );
    println!("  laplacian (ν = 1)   {:.3e}", mean_norm(&laplacian));
    Ok(())
}
