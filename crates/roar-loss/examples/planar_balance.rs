//! Loss balance (`docs/method.md#decision-balance-of-the-planar-term`): gradient norms of the
//! render loss and of the raw planar loss on an icosphere source of radius 0.5 against a sphere
//! target of radius R, so the default `PlanarOptions::scale` can be chosen to make both terms
//! comparable at weight 1.
//!
//! Run: `cargo run -p roar-loss --example planar_balance [resolution] [levels...]`.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_loss::{Loss, PlanarLoss, PlanarOptions};
use roar_mesh::shapes::icosphere;
use roar_render::{LossKind, RenderOptions, render, render_loss_and_grad, star_cameras};

fn sphere(radius: f64, level: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (p, t) = icosphere(level).to_triangles();
    (p.iter().map(|p| *p * radius).collect(), t)
}

fn sphere_cloud(radius: f64, n: usize) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut normals = Vec::with_capacity(n);
    while normals.len() < n {
        let v = DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - DVec3::ONE;
        if v.length() > 1e-3 && v.length() <= 1.0 {
            normals.push(v.normalize());
        }
    }
    (normals.iter().map(|n| *n * radius).collect(), normals)
}

/// (L2 norm over all vertices, mean per-vertex norm, median per-vertex norm).
fn norms(g: &[DVec3]) -> (f64, f64, f64) {
    let l2 = g.iter().map(|g| g.length_squared()).sum::<f64>().sqrt();
    let mut per: Vec<f64> = g.iter().map(|g| g.length()).collect();
    let mean = per.iter().sum::<f64>() / per.len() as f64;
    per.sort_by(f64::total_cmp);
    (l2, mean, per[per.len() / 2])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let resolution: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(256);
    let levels: Vec<u32> = if args.len() > 2 {
        args[2..].iter().filter_map(|s| s.parse().ok()).collect()
    } else {
        vec![3]
    };
    let cameras = star_cameras(6, 6, resolution, resolution);
    let opts = RenderOptions::default();
    println!("36 views at {resolution}², source icosphere radius 0.5, raw planar (scale 1)");
    println!(
        "level faces R | render |g|2 mean median | planar |g|2 mean median | ratio mean render/raw planar, render/default-scaled planar"
    );
    for &level in &levels {
        let (sp, st) = sphere(0.5, level);
        for big_r in [0.502, 0.51, 0.55] {
            let (tp, tt) = sphere(big_r, 6);
            let targets: Vec<_> = render(&tp, &tt, &cameras, &opts)?
                .views
                .into_iter()
                .map(|v| v.rgba)
                .collect();
            let (_, g_render) =
                render_loss_and_grad(&sp, &st, &cameras, &targets, &opts, LossKind::L1)?;
            let (points, normals) = sphere_cloud(big_r, 200_000);
            let mut planar = PlanarLoss::new(&points, &normals, &PlanarOptions::raw())?;
            let (_, g_planar) = planar.value_and_grad(&sp, &st)?;
            let r = norms(&g_render);
            let p = norms(&g_planar);
            println!(
                "{level} {} {big_r} | {:.3e} {:.3e} {:.3e} | {:.3e} {:.3e} {:.3e} | {:.1} {:.2}",
                st.len(),
                r.0,
                r.1,
                r.2,
                p.0,
                p.1,
                p.2,
                r.1 / p.1,
                r.1 / (p.1 * roar_loss::planar::SPHERE_BALANCED_PLANAR_SCALE)
            );
        }
    }
    Ok(())
}
