//! A glTF scene (several nodes, nested, one mirrored by a negative scale) reconstructs to the
//! same bytes as the same soup written as OBJ, with the node transforms applied by hand to the
//! glTF's own f32 values.

use glam::DVec3;
use roar_cli::pipeline::{ReconstructConfig, Reconstruction, SoupShape};
use roar_io::TriangleSoup;

/// Toy settings (as in `reconstruct_small`): fast enough for the default test run.
fn toy_config() -> ReconstructConfig {
    ReconstructConfig {
        faces: 200,
        iterations: 4,
        init_resolution: 32,
        init_max_faces: 4000,
        working_budget_min: 600,
        views_per_axis: 2,
        render_resolution: 64,
        point_cloud_samples: 5000,
        sharp_edge_samples: 1000,
        planar_max_samples: 5000,
        split_interval: 3,
        smoothing_interval: 2,
        ..ReconstructConfig::default()
    }
}

/// A `.glb` holding one mesh (f32 positions, u32 indices) instanced by three nodes:
/// node 0 translated by (0.5, 0, 0); node 1 translated by (0, 1, 0) with child node 2, mirrored by
/// scale (-1, 1, 1) and translated by (3, 0, 0).
fn glb(points: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut bin: Vec<u8> = points
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let positions_len = bin.len();
    bin.extend(triangles.iter().flatten().flat_map(|i| i.to_le_bytes()));
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in points {
        for c in 0..3 {
            min[c] = min[c].min(p[c]);
            max[c] = max[c].max(p[c]);
        }
    }
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
        "nodes":[{{"mesh":0,"translation":[0.5,0,0]}},{{"children":[2],"translation":[0,1,0]}},
                 {{"mesh":0,"scale":[-1,1,1],"translation":[3,0,0]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":{min:?},"max":{max:?}}},
                     {{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{positions_len}}},
                       {{"buffer":0,"byteOffset":{positions_len},"byteLength":{}}}],
        "buffers":[{{"byteLength":{}}}]}}"#,
        points.len(),
        triangles.len() * 3,
        bin.len() - positions_len,
        bin.len(),
    );
    let mut json = json.into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// Reconstructs the soup read from `path` at toy settings and returns the OBJ bytes written.
fn reconstruct_to_obj(path: &std::path::Path, out: &std::path::Path) -> Vec<u8> {
    let soup = roar_io::read_mesh(path).unwrap_or_else(|e| panic!("{e}"));
    let config = toy_config();
    let mut shape = SoupShape::new("scene", &soup.positions, &soup.triangles, &config);
    let result = Reconstruction::new(config)
        .run(&mut shape, &mut |_| {})
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    roar_io::write_mesh(out, &TriangleSoup::new(result.positions, result.triangles)).unwrap();
    std::fs::read(out).unwrap()
}

#[test]
fn a_gltf_scene_reconstructs_like_its_soup_as_obj() {
    let chair = roar_cli::example::chair_soup();
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
