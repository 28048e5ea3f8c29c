//! Soups as the library crates want them: welded at bit-identical positions and stripped of
//! unreferenced vertices.

use glam::DVec3;
use roar_io::TriangleSoup;

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
