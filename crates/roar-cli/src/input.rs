//! Turning what a user hands us into what the library crates want: soups welded at bit-identical
//! positions, stripped of unreferenced vertices, and half-edge meshes where a closed manifold is
//! required.

use std::path::Path;

use anyhow::Context;
use glam::DVec3;
use roar_io::TriangleSoup;
use roar_mesh::Mesh;

/// Keeps only the vertices some triangle references, renumbering the triangles (first use order).
pub fn drop_unreferenced(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut new_index = vec![u32::MAX; positions.len()];
    let mut kept = Vec::new();
    let triangles = triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                let slot = &mut new_index[v as usize];
                if *slot == u32::MAX {
                    *slot = kept.len() as u32;
                    kept.push(positions[v as usize]);
                }
                *slot
            })
        })
        .collect();
    (kept, triangles)
}

/// The soup welded at bit-identical positions, without unreferenced vertices.
pub fn welded_referenced(soup: &TriangleSoup) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (welded, _) = soup.welded();
    drop_unreferenced(&welded.positions, &welded.triangles)
}

/// Reads `path` as a closed, oriented 2-manifold (after welding bit-identical positions), or says
/// in one line why it is not one.
pub fn read_closed_mesh(path: &Path) -> anyhow::Result<Mesh> {
    let soup = roar_io::read_mesh(path)?;
    let (positions, triangles) = welded_referenced(&soup);
    Mesh::from_triangles(positions, &triangles).with_context(|| {
        format!(
            "{} is not a closed, oriented 2-manifold (run `roar init` on it first)",
            path.display()
        )
    })
}

/// Writes a half-edge mesh to any supported format (atomically).
pub fn write_mesh(path: &Path, mesh: &Mesh) -> anyhow::Result<()> {
    let (positions, triangles) = mesh.to_triangles();
    roar_io::write_mesh(path, &TriangleSoup::new(positions, triangles))?;
    Ok(())
}

/// Refuses a face budget no closed mesh can have, up front: odd (3F = 2E) or below the 4 faces
/// of a tetrahedron; the message names only budgets that work.
pub fn check_even_budget(faces: usize) -> anyhow::Result<()> {
    crate::budget::check_budget("--faces", faces, 4).map_err(anyhow::Error::msg)
}
