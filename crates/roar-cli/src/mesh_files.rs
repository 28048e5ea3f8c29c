//! Closed meshes read from and written to the user's files, for the commands that need a closed
//! manifold (`decimate`, `init`).

use std::path::Path;

use anyhow::Context;
use roar::input::welded_referenced;
use roar_io::TriangleSoup;
use roar_mesh::Mesh;

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

/// A clap value parser for `--faces`: a non-negative whole number, with a message that says so
/// for `-10` or `ten` (clap would otherwise read `-10` as the flags `-1 -0`).
pub fn parse_faces(text: &str) -> Result<usize, String> {
    text.trim()
        .parse::<usize>()
        .map_err(|_| format!("{text:?} is not a face count (a positive even whole number)"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_faces_explains_negative_numbers() {
        assert_eq!(parse_faces("5000"), Ok(5000));
        assert!(parse_faces("-10").unwrap_err().contains("not a face count"));
        assert!(parse_faces("ten").is_err());
    }
}
