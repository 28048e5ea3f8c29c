//! `roar info FILE [--json]`: what is in a mesh file, and whether it is a closed 2-manifold.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use glam::DVec3;
use roar_mesh::Mesh;
use serde::Serialize;

/// Arguments of `roar info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Mesh file (OBJ, PLY, STL or OFF; extension case-insensitive).
    pub file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// What `roar info` reports.
#[derive(Debug, Serialize)]
pub struct Info {
    /// Vertices as stored in the file.
    pub vertices: usize,
    /// Triangles after polygons were triangulated (ear clipping in each polygon's plane).
    pub faces: usize,
    /// Faces of the file with more than 3 corners.
    pub polygons: usize,
    /// Polygons that could not be triangulated cleanly (no plane, a self-intersecting outline,
    /// too many corners): fan-triangulated, at least in part, so their triangles may overlap.
    pub polygons_unclean: usize,
    /// Faces of the file with fewer than 3 corners: they bound no surface, so they were skipped.
    pub faces_skipped: usize,
    /// Distinct vertex positions (bit-identical positions welded).
    pub vertices_welded: usize,
    /// Axis-aligned bounding box of the referenced vertices, `[min, max]`.
    pub bbox: [[f64; 3]; 2],
    /// Whether the welded mesh is a closed, oriented 2-manifold.
    pub closed_manifold: bool,
    /// Genus (summed over components), if a closed manifold.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub genus: Option<usize>,
    /// Connected components, if a closed manifold.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub components: Option<usize>,
    /// The first reason the welded mesh is not a closed manifold.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_manifold_because: Option<String>,
}

/// Runs `roar info`.
pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    let info = info(&args.file)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        print!("{}", format_text(&args.file, &info));
    }
    Ok(())
}

/// Reads `path` and gathers its [`Info`].
pub fn info(path: &std::path::Path) -> anyhow::Result<Info> {
    let soup = roar_io::read_mesh(path)?;
    let (welded, _) = soup.welded();
    let (positions, triangles) =
        roar::input::drop_unreferenced(&welded.positions, &welded.triangles);
    let bbox = bounding_box(&positions)
        .with_context(|| format!("{}: no referenced vertices", path.display()))?;
    let mut info = Info {
        vertices: soup.positions.len(),
        faces: soup.triangles.len(),
        polygons: soup.n_polygons,
        polygons_unclean: soup.n_polygons_unclean,
        faces_skipped: soup.n_faces_skipped,
        vertices_welded: welded.positions.len(),
        bbox,
        closed_manifold: false,
        genus: None,
        components: None,
        not_manifold_because: None,
    };
    match Mesh::from_triangles(positions, &triangles) {
        Ok(mesh) => {
            info.closed_manifold = true;
            info.components = Some(mesh.components().0);
            info.genus = Some(mesh.genus());
        }
        Err(reason) => info.not_manifold_because = Some(reason.to_string()),
    }
    Ok(info)
}

fn format_text(path: &std::path::Path, info: &Info) -> String {
    let [lo, hi] = info.bbox;
    let mut text = format!(
        "{}\n  vertices  {} ({} distinct positions)\n  faces     {}\n  bbox      [{}, {}, {}] .. [{}, {}, {}]\n",
        path.display(),
        info.vertices,
        info.vertices_welded,
        info.faces,
        lo[0],
        lo[1],
        lo[2],
        hi[0],
        hi[1],
        hi[2],
    );
    if info.polygons > 0 {
        text.push_str(&format!(
            "  polygons  {} triangulated, {} not cleanly (no plane or a self-intersecting outline)\n",
            info.polygons, info.polygons_unclean
        ));
    }
    if info.faces_skipped > 0 {
        text.push_str(&format!(
            "  skipped   {} face(s) with fewer than 3 corners (no surface)\n",
            info.faces_skipped
        ));
    }
    match (&info.not_manifold_because, info.genus, info.components) {
        (None, Some(genus), Some(components)) => text.push_str(&format!(
            "  closed 2-manifold: yes, genus {genus}, {components} component(s)\n"
        )),
        (Some(reason), _, _) => {
            text.push_str(&format!("  closed 2-manifold: no ({reason})\n"));
        }
        _ => {}
    }
    text
}

fn bounding_box(positions: &[DVec3]) -> Option<[[f64; 3]; 2]> {
    let first = *positions.first()?;
    let (lo, hi) = positions
        .iter()
        .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    Some([lo.to_array(), hi.to_array()])
}
