//! `roar eval MESH [--ref REF] [--json]`: topology, quality, orientation and self-intersections of
//! a mesh, and its fidelity to a reference (sampled and exact Chamfer, Hausdorff, normal cosine).

use std::path::PathBuf;

use clap::Args;
use roar_eval::{ChamferOptions, EvalOptions, Report};

/// Arguments of `roar eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// The mesh to measure (any soup; OBJ, PLY, STL or OFF).
    pub mesh: PathBuf,
    /// Reference mesh for Chamfer, Hausdorff and normal similarity.
    #[arg(long = "ref")]
    pub reference: Option<PathBuf>,
    /// Print the JSON report instead of text.
    #[arg(long)]
    pub json: bool,
    /// Area-weighted samples per side for the fidelity metrics, sampled and exact (at least 1 with
    /// `--ref`).
    #[arg(long, default_value_t = ChamferOptions::default().samples)]
    pub samples: usize,
    /// Seed of the sampling (the reference's samples use seed + 1).
    #[arg(long, default_value_t = ChamferOptions::default().seed)]
    pub seed: u64,
}

/// Runs `roar eval`. With `--ref`, the fidelity section is never dropped silently: `--samples 0`
/// is refused up front, and a mesh or reference without area (nothing to sample) is an error
/// that says which.
pub fn run(args: &EvalArgs) -> anyhow::Result<()> {
    if args.reference.is_some() && args.samples == 0 {
        anyhow::bail!(
            "--samples 0 with --ref: the fidelity metrics need at least 1 sample per side"
        );
    }
    let mesh = roar_io::read_mesh(&args.mesh)?;
    let reference = args
        .reference
        .as_deref()
        .map(roar_io::read_mesh)
        .transpose()?;
    let options = EvalOptions {
        chamfer: ChamferOptions {
            samples: args.samples,
            seed: args.seed,
        },
        ..EvalOptions::default()
    };
    let report = roar_eval::evaluate(
        &mesh.positions,
        &mesh.triangles,
        reference
            .as_ref()
            .map(|r| (r.positions.as_slice(), r.triangles.as_slice())),
        &options,
    )?;
    if let (Some(reference_path), Some(reference)) = (&args.reference, &reference)
        && report.fidelity.is_none()
    {
        let zero = |soup: &roar_io::TriangleSoup| {
            roar_mesh::spatial::sample_surface(&soup.positions, &soup.triangles, 1, 0)
                .points
                .is_empty()
        };
        let which = if zero(reference) {
            reference_path
        } else {
            &args.mesh
        };
        anyhow::bail!(
            "{}: the surface has zero area, so there is nothing to sample for the fidelity \
             metrics (Chamfer, Hausdorff, normal cosine)",
            which.display()
        );
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", format_text(&report));
    }
    Ok(())
}

/// A short human-readable summary of a report.
pub fn format_text(report: &Report) -> String {
    let t = &report.topology_welded;
    let mut text = format!(
        "welded topology: {} vertices, {} faces, {} components, watertight {}\n  \
         boundary edges {}, non-manifold edges {}, non-manifold vertices {}, \
         degenerate faces {}, inconsistent edges {}\n",
        t.vertices_referenced,
        t.faces,
        t.components,
        if t.watertight { "yes" } else { "no" },
        t.boundary_edges,
        t.nonmanifold_edges,
        t.nonmanifold_vertices,
        t.degenerate_faces,
        t.inconsistent_edges,
    );
    if let Some(genus) = t.genus {
        text.push_str(&format!(
            "  euler characteristic {}, genus {genus}\n",
            t.euler_characteristic
        ));
    }
    if let Some(median) = report.quality.aspect_ratio_median {
        text.push_str(&format!("aspect ratio median {median:.4}\n"));
    }
    text.push_str(&format!(
        "signed volume {:.6e}\n",
        report.orientation.signed_volume
    ));
    if let Some(s) = &report.self_intersections {
        text.push_str(&format!(
            "self-intersecting faces {} ({:.4} %), {} after the ε discount\n",
            s.faces,
            100.0 * s.fraction,
            s.faces_eps_discounted
        ));
    }
    if let Some(f) = &report.fidelity {
        text.push_str(&format!(
            "chamfer L2 {:.6e} ({:.6e} of the reference diagonal), hausdorff/diag {:.6e}\n\
             normal cosine {:.4} (absolute {:.4})\n",
            f.chamfer_l2,
            f.chamfer_l2_over_diag,
            f.hausdorff_over_diag,
            f.normal_cosine,
            f.normal_cosine_abs
        ));
        text.push_str(&format!(
            "exact chamfer {:.6e} ({:.6e} of the reference diagonal), hausdorff/diag {:.6e}\n\
             exact normal cosine {:.4} (absolute {:.4})\n",
            f.chamfer_exact,
            f.chamfer_exact_over_diag,
            f.hausdorff_exact_over_diag,
            f.normal_cosine_exact,
            f.normal_cosine_exact_abs
        ));
    }
    text
}
