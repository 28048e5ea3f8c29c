//! Vertex normals as the ROAR losses and the finish use them (spec §2.2).

use glam::DVec3;

/// ROAR vertex normals (spec §2.2): `N_v = Σ_{f∋v} A_f θ_{f,v} n_f`, normalized (area **times**
/// corner angle). Degenerate faces (|cross| ≤ 1e-9) use normal (1,0,0) and area 1e-9, as the
/// reference does. Vertices with a vanishing sum (or unreferenced) get a zero normal.
/// Triangles with an out-of-range index are skipped.
pub fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut sums = vec![DVec3::ZERO; positions.len()];
    for tri in triangles {
        let (Some(&p0), Some(&p1), Some(&p2)) = (
            positions.get(tri[0] as usize),
            positions.get(tri[1] as usize),
            positions.get(tri[2] as usize),
        ) else {
            continue;
        };
        let c = [p0, p1, p2];
        let cross = (c[1] - c[0]).cross(c[2] - c[0]);
        let len = cross.length();
        let (normal, area) = if len > 1e-9 {
            (cross / len, 0.5 * len)
        } else {
            (DVec3::X, 1e-9)
        };
        for k in 0..3 {
            let e1 = (c[(k + 1) % 3] - c[k]).normalize_or_zero();
            let e2 = (c[(k + 2) % 3] - c[k]).normalize_or_zero();
            let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
            sums[tri[k] as usize] += area * angle * normal;
        }
    }
    sums.into_iter().map(|n| n.normalize_or_zero()).collect()
}
