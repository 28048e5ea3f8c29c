//! A glTF scene (several nodes, nested, one mirrored by a negative scale) reconstructs to the
//! same bytes as the same soup written as OBJ, with the node transforms applied by hand to the
//! glTF's own f32 values.

mod common;

use glam::DVec3;
use roar::Reconstruction;
use roar_io::TriangleSoup;

/// A `.glb` holding one mesh (f32 positions, u32 indices) instanced twice: node 0 translated by
/// (0.5, 0, 0); node 2 translated by (0, 1, 0) with child node 1, mirrored by scale (-1, 1, 1)
/// and translated by (3, 0, 0).
fn glb(points: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut b = common::gltf::GltfBuilder::default();
    let positions = b.add_positions(points);
    let flat: Vec<u32> = triangles.iter().flatten().copied().collect();
    let indices = b.add_indices_u32(&flat);
    let mesh = b.add_mesh(positions, Some(indices), None);
    let first = b.add_node(&format!(r#""mesh":{mesh},"translation":[0.5,0,0]"#));
    let mirrored = b.add_node(&format!(
        r#""mesh":{mesh},"scale":[-1,1,1],"translation":[3,0,0]"#
    ));
    let parent = b.add_node(&format!(r#""children":[{mirrored}],"translation":[0,1,0]"#));
    b.add_scene(&[first, parent]);
    b.scene = Some(0);
    b.glb()
}

/// Reconstructs the soup read from `path` at toy settings and returns the OBJ bytes written.
fn reconstruct_to_obj(path: &std::path::Path, out: &std::path::Path) -> Vec<u8> {
    let soup = roar_io::read_mesh(path).unwrap_or_else(|e| panic!("{e}"));
    let result = Reconstruction::new(common::toy_config(200, 4))
        .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    roar_io::write_mesh(out, &TriangleSoup::new(result.positions, result.triangles)).unwrap();
    std::fs::read(out).unwrap()
}

#[test]
fn a_gltf_scene_reconstructs_like_its_soup_as_obj() {
    let chair = roar::example::chair_soup();
    let points: Vec<[f32; 3]> = chair
        .positions
        .iter()
        .map(|p| p.to_array().map(|c| c as f32))
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let gltf_path = dir.path().join("scene.glb");
    std::fs::write(&gltf_path, glb(&points, &chair.triangles)).unwrap();

    // The same soup by hand: each instance's transformed f32 values, mirrored copy re-wound.
    let f64s = |p: &[f32; 3]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    let mut positions: Vec<DVec3> = points
        .iter()
        .map(|p| f64s(p) + DVec3::new(0.5, 0.0, 0.0))
        .collect();
    positions.extend(
        points
            .iter()
            .map(|p| f64s(p) * DVec3::new(-1.0, 1.0, 1.0) + DVec3::new(3.0, 1.0, 0.0)),
    );
    let n = points.len() as u32;
    let mut triangles = chair.triangles.clone();
    triangles.extend(
        chair
            .triangles
            .iter()
            .map(|&[a, b, c]| [a + n, c + n, b + n]),
    );
    let by_hand = TriangleSoup::new(positions, triangles);
    let obj_path = dir.path().join("scene.obj");
    roar_io::write_mesh(&obj_path, &by_hand).unwrap();

    let read = roar_io::read_mesh(&gltf_path).unwrap();
    assert_eq!(read.triangles, by_hand.triangles);
    for (a, b) in read.positions.iter().zip(&by_hand.positions) {
        assert_eq!(a.to_array(), b.to_array());
    }
    assert_eq!(read.positions.len(), by_hand.positions.len());

    let from_gltf = reconstruct_to_obj(&gltf_path, &dir.path().join("a.obj"));
    let from_obj = reconstruct_to_obj(&obj_path, &dir.path().join("b.obj"));
    assert!(!from_gltf.is_empty());
    assert!(from_gltf == from_obj, "the two reconstructions differ");
}
