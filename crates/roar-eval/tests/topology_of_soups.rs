//! Topology counts on small hand-built soups, each probing one rule.

mod common;

use common::shapes::{cube, torus};
use glam::DVec3;
use roar_eval::{TopologyStats, signed_volume, topology, weld_bit_identical};

fn square() -> Vec<DVec3> {
    vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y]
}

#[test]
fn two_triangles_sharing_an_edge_form_a_disc() {
    let t = topology(&square(), &[[0, 1, 2], [0, 2, 3]]);
    assert_eq!(t.edges, 5);
    assert_eq!(t.boundary_edges, 4);
    assert_eq!(t.boundary_loops, 1);
    assert_eq!((t.nonmanifold_edges, t.nonmanifold_vertices), (0, 0));
    assert_eq!(t.inconsistent_edges, 0);
    assert_eq!(t.components, 1);
    assert!(!t.watertight);
    assert_eq!(t.euler_characteristic, 1);
    assert_eq!(t.genus, None);
}

#[test]
fn three_triangles_on_one_edge_make_it_non_manifold() {
    let p = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::new(0.5, -1.0, 0.3),
    ];
    let t = topology(&p, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
    assert_eq!(t.nonmanifold_edges, 1);
    assert_eq!(t.boundary_edges, 6);
    // The three faces are joined through the shared edge: one fan at each end, one component.
    assert_eq!(t.nonmanifold_vertices, 0);
    assert_eq!(t.components, 1);
    assert_eq!(
        t.inconsistent_edges, 0,
        "non-manifold edges are not winding checks"
    );
}

#[test]
fn bow_tie_vertex_is_non_manifold() {
    let p = vec![
        DVec3::ZERO,
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(1.0, -1.0, 0.0),
        DVec3::new(-1.0, 1.0, 0.0),
        DVec3::new(-1.0, -1.0, 0.0),
    ];
    let t = topology(&p, &[[0, 2, 1], [0, 3, 4]]);
    assert_eq!(t.nonmanifold_vertices, 1);
    assert_eq!(t.nonmanifold_edges, 0);
    assert_eq!(t.components, 2, "a shared vertex does not join components");
    assert_eq!(t.boundary_edges, 6);
    // Boundary loops are connected pieces of the boundary graph: the two triangles' rims touch.
    assert_eq!(t.boundary_loops, 1);
}

#[test]
fn square_with_a_hole_has_two_boundary_loops() {
    // 4×4 grid of vertices, 3×3 quads, the middle quad left out.
    let p: Vec<DVec3> = (0..16)
        .map(|i| DVec3::new((i % 4) as f64, (i / 4) as f64, 0.0))
        .collect();
    let mut tris = Vec::new();
    for y in 0..3u32 {
        for x in 0..3u32 {
            if (x, y) == (1, 1) {
                continue;
            }
            let a = y * 4 + x;
            tris.push([a, a + 1, a + 5]);
            tris.push([a, a + 5, a + 4]);
        }
    }
    let t = topology(&p, &tris);
    assert_eq!(t.boundary_edges, 12 + 4);
    assert_eq!(t.boundary_loops, 2);
    assert_eq!(t.euler_characteristic, 0, "an annulus");
    assert_eq!((t.components, t.nonmanifold_vertices), (1, 0));
}

#[test]
fn same_direction_traversal_is_inconsistent_winding() {
    let t = topology(&square(), &[[0, 1, 2], [0, 3, 2]]);
    assert_eq!(t.inconsistent_edges, 1);
    let t = topology(&square(), &[[0, 1, 2], [0, 2, 3]]);
    assert_eq!(t.inconsistent_edges, 0);
}

#[test]
fn duplicates_are_split_by_orientation() {
    let p = square();
    // Same orientation twice (one rotated), then an inward twin.
    let t = topology(&p, &[[0, 1, 2], [1, 2, 0], [2, 1, 0]]);
    assert_eq!((t.duplicate_faces_same, t.duplicate_faces_opposite), (1, 1));
    let t = topology(&p, &[[0, 1, 2], [0, 2, 1]]);
    assert_eq!((t.duplicate_faces_same, t.duplicate_faces_opposite), (0, 1));
    let t = topology(&p, &[[0, 1, 2], [0, 1, 2], [0, 1, 2], [0, 2, 3]]);
    assert_eq!((t.duplicate_faces_same, t.duplicate_faces_opposite), (2, 0));
    // Three copies make all their edges non-manifold (3 or 4 incident triangles).
    assert_eq!(t.nonmanifold_edges, 3);
}

#[test]
fn degenerate_faces_count_but_repeated_vertices_stay_out_of_topology() {
    let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::X * 2.0];
    let t = topology(&p, &[[0, 1, 2], [0, 0, 1], [0, 1, 3]]);
    assert_eq!(t.degenerate_faces, 2, "one repeated index, one zero area");
    assert_eq!(t.faces, 3);
    // Topology over [0,1,2] and the zero-area [0,1,3] (distinct indices): edge 0–1 is shared.
    assert_eq!(t.edges, 5);
    assert_eq!(t.boundary_edges, 4);
    assert_eq!(t.vertices_referenced, 4);
}

fn assert_closed_genus(t: &TopologyStats, components: usize, genus: i64) {
    assert!(t.watertight);
    assert_eq!(
        t.boundary_edges + t.nonmanifold_edges + t.nonmanifold_vertices,
        0
    );
    assert_eq!(t.inconsistent_edges, 0);
    assert_eq!(t.components, components);
    assert_eq!(t.genus, Some(genus));
}

#[test]
fn closed_cube_is_a_watertight_sphere_of_volume_one() {
    let (p, tris) = cube();
    let t = topology(&p, &tris);
    assert_closed_genus(&t, 1, 0);
    assert_eq!(t.euler_characteristic, 2);
    assert!((signed_volume(&p, &tris) - 1.0).abs() < 1e-12);
    let inverted: Vec<[u32; 3]> = tris.iter().map(|&[a, b, c]| [a, c, b]).collect();
    assert!((signed_volume(&p, &inverted) + 1.0).abs() < 1e-12);
}

#[test]
fn hand_built_torus_has_genus_one() {
    let (p, tris) = torus(2.0, 0.5, 24, 12);
    let t = topology(&p, &tris);
    assert_closed_genus(&t, 1, 1);
    assert_eq!(t.euler_characteristic, 0);
    let exact = 2.0 * std::f64::consts::PI.powi(2) * 2.0 * 0.25;
    let v = signed_volume(&p, &tris);
    // Inscribed polygons (12 around the tube, 24 around the axis) lose about 5.6 % of the volume.
    assert!(v > 0.92 * exact && v < exact, "volume {v} vs {exact}");
}

#[test]
fn two_disjoint_cubes_are_two_genus_zero_components() {
    let (mut p, mut tris) = cube();
    let n = p.len() as u32;
    p.extend(p.clone().iter().map(|q| *q + DVec3::splat(3.0)));
    tris.extend(tris.clone().iter().map(|t| t.map(|i| i + n)));
    let t = topology(&p, &tris);
    assert_closed_genus(&t, 2, 0);
    assert_eq!(t.euler_characteristic, 4);
}

#[test]
fn welding_an_stl_style_cube_restores_the_closed_cube() {
    let (p, tris) = cube();
    let mut soup_p = Vec::new();
    let mut soup_t = Vec::new();
    for t in &tris {
        let base = soup_p.len() as u32;
        // −0.0 and 0.0 are the same position and must weld.
        soup_p.extend(t.map(|i| p[i as usize]));
        soup_t.push([base, base + 1, base + 2]);
    }
    soup_p[0] = DVec3::new(-0.0, -0.0, -0.0);
    assert_eq!(p[tris[0][0] as usize], DVec3::ZERO);
    let raw = topology(&soup_p, &soup_t);
    assert_eq!((raw.boundary_edges, raw.components), (36, 12));
    let (wp, wt) = weld_bit_identical(&soup_p, &soup_t);
    assert_eq!(wp.len(), 8);
    let t = topology(&wp, &wt);
    assert_closed_genus(&t, 1, 0);
    assert_eq!(t.euler_characteristic, 2);
}
