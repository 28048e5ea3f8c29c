//! roar as a library, to copy: reconstruct the shipped example soup with a swapped loss (the
//! paper's render and planar terms plus a term of your own) and a swapped block (a block of
//! your own in the schedule), at toy settings so it runs in seconds.
//!
//! `cargo run --release -p roar --example library [OUTPUT.obj]` (default
//! `target/library.obj`) writes the reconstruction and prints what the run did.

use std::path::PathBuf;

use glam::DVec3;
use roar::example::chair_soup;
use roar::{
    FinishConfig, InitConfig, LossConfig, OptimizeConfig, PipelineError, Prepared,
    ReconstructConfig, Reconstruction, ScheduledBlock, TargetConfig, default_loss,
};
use roar_io::TriangleSoup;
use roar_loss::{Loss, LossError, WeightedSum};
use roar_mesh::spatial::self_intersecting_faces;
use roar_mesh::{Mesh, TrackedMesh};
use roar_ops::blocks::block::{Block, BlockContext, BlockStats};
use roar_ops::blocks::flips::{FlipOptions, flip_edges};

/// Any error, as one line for the terminal.
type Result<T, E = Box<dyn std::error::Error>> = std::result::Result<T, E>;

/// A loss term of our own: the mean squared edge length (each edge counted once per face),
/// which pulls the vertices towards even spacing. A [`Loss`] returns its value and its
/// gradient with respect to every vertex position.
struct EdgeLength;

impl Loss for EdgeLength {
    fn name(&self) -> &'static str {
        "edge_length"
    }

    fn value_and_grad(
        &mut self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
    ) -> Result<(f64, Vec<DVec3>), LossError> {
        let count = (3 * triangles.len()).max(1) as f64;
        let mut value = 0.0;
        let mut grad = vec![DVec3::ZERO; positions.len()];
        for t in triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                let d = positions[a] - positions[b];
                value += d.length_squared() / count;
                grad[a] += 2.0 * d / count;
                grad[b] -= 2.0 * d / count;
            }
        }
        Ok((value, grad))
    }
}

/// A block of our own: the valence-improving edge flips on their own schedule. A
/// [`Block`] edits the mesh through a [`TrackedMesh`]; flips keep the vertex set, so they go
/// through `with_fixed_vertices` (an operator that adds or removes vertices would call the
/// tracked mesh's own methods, which keep the optimizer's per-vertex rows in step).
struct ValenceFlips;

impl Block for ValenceFlips {
    fn name(&self) -> &'static str {
        "valence_flips"
    }

    fn apply(&mut self, mesh: &mut TrackedMesh, _ctx: &BlockContext) -> BlockStats {
        let mut stats = mesh.with_fixed_vertices(|mesh| flip_edges(mesh, &FlipOptions::default()));
        stats.name = self.name();
        stats
    }
}

/// The objective: the paper's `λ1·render + λ2·planar` ([`default_loss`], what `roar reconstruct`
/// optimizes) plus `0.5·edge_length`. The factory gets what the input shape gave, in rig
/// coordinates; the report lists the loss by term (`weighted_sum`, the paper's, and
/// `edge_length`).
fn loss_with_edge_term(prepared: &Prepared) -> Result<Box<dyn Loss>, PipelineError> {
    Ok(Box::new(
        WeightedSum::default()
            .with(1.0, default_loss(prepared)?)
            .with(0.5, Box::new(EdgeLength)),
    ))
}

/// The largest difference between `EdgeLength`'s gradient and central finite differences on
/// `mesh`, relative to the largest gradient entry: a new loss term's gradient is checked
/// before it drives a run.
fn edge_length_gradient_error(mesh: &Mesh) -> Result<f64> {
    let (positions, triangles) = mesh.to_triangles();
    let (_, grad) = EdgeLength.value_and_grad(&positions, &triangles)?;
    let scale = grad
        .iter()
        .map(|g| g.abs().max_element())
        .fold(0.0, f64::max);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for (v, g) in grad.iter().enumerate().step_by(7) {
        for axis in 0..3 {
            let mut moved = positions.clone();
            moved[v][axis] += h;
            let (up, _) = EdgeLength.value_and_grad(&moved, &triangles)?;
            moved[v][axis] -= 2.0 * h;
            let (down, _) = EdgeLength.value_and_grad(&moved, &triangles)?;
            worst = worst.max(((up - down) / (2.0 * h) - g[axis]).abs());
        }
    }
    Ok(worst / scale)
}

fn main() -> Result<()> {
    let output = std::env::args_os()
        .nth(1)
        .map_or_else(|| PathBuf::from("target/library.obj"), PathBuf::from);

    let error = edge_length_gradient_error(&roar_mesh::shapes::icosphere(2))?;
    if error >= 1e-6 {
        return Err(format!("edge-length gradient off by {error:e}").into());
    }

    // Toy settings (coarse init, 4 views of 64², 30 iterations) so the example runs in
    // seconds; `ReconstructConfig::default()` is what `roar reconstruct` uses.
    let config = ReconstructConfig {
        faces: 600,
        target: TargetConfig {
            views_per_axis: 2,
            render_resolution: 64,
            point_cloud_samples: 5000,
            sharp_edge_samples: 1000,
            ..Default::default()
        },
        init: InitConfig {
            init_resolution: 48,
            init_max_faces: 4000,
            ..Default::default()
        },
        loss: LossConfig {
            planar_max_samples: 5000,
            ..Default::default()
        },
        optimize: OptimizeConfig {
            iterations: 30,
            working_budget_min: 1200,
            split_interval: 5,
            ..Default::default()
        },
        finish: FinishConfig {
            polish_iterations: 5,
            ..Default::default()
        },
        ..ReconstructConfig::default()
    };
    let mut reconstruction = Reconstruction::new(config);
    // Swap the loss.
    reconstruction.loss_factory = Box::new(loss_with_edge_term);
    // Swap a block: the default schedule is Face Collapse, Face Split and tangential smoothing
    // (off by default); our flips take the smoothing's place, every 5 iterations after the first.
    reconstruction
        .blocks
        .retain(|b| b.block.name() != "tangential_smoothing");
    reconstruction.blocks.push(ScheduledBlock {
        block: Box::new(ValenceFlips),
        every: 5,
        skip_first: true,
    });

    let soup = chair_soup();
    let out = reconstruction.run_soup(&soup.positions, &soup.triangles, &mut |_| {})?;

    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles)?;
    let crossing = self_intersecting_faces(&out.positions, &out.triangles)
        .iter()
        .filter(|&&c| c)
        .count();
    let last = out.stats.optimize.history.last().map(|r| &r.terms);
    println!(
        "{} faces, genus {}, {crossing} self-intersecting faces; loss {:.4} -> {:.4}; \
         last loop terms {last:?}; accepted operations per block {:?}",
        out.triangles.len(),
        mesh.genus(),
        out.stats.optimize.loss_first,
        out.stats.optimize.loss_last,
        out.stats.optimize.block_accepted,
    );
    // The pipeline's promises hold whatever the loss and blocks: `from_triangles` accepted a
    // closed, oriented 2-manifold; the budget is exact and no face crosses another.
    if out.triangles.len() != reconstruction.config.faces || crossing != 0 {
        return Err("the output breaks the pipeline's promises".into());
    }
    roar_io::write_mesh(&output, &TriangleSoup::new(out.positions, out.triangles))?;
    println!("wrote {}", output.display());
    Ok(())
}
