//! glTF 2.0 input: node transforms (nested, negative scale), primitive modes, indices or none,
//! sparse and quantized accessors, the three ways of storing the buffer, scene choice, and the
//! inputs refused with a message (points, lines, compressed files, broken accessors).

mod common;

use common::gltf::{GltfBuilder, bounds, tetrahedron};
use glam::DVec3;
use roar_io::{TriangleSoup, read_gltf, read_mesh};

/// Reads `bytes` as `x.glb` or `x.gltf` through `read_mesh` (the path the CLI takes).
fn read_named(name: &str, bytes: &[u8]) -> Result<TriangleSoup, String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    read_mesh(&path).map_err(|e| e.to_string())
}

/// Six times the signed volume enclosed by the soup's triangles (positive when outward).
fn signed_volume6(soup: &TriangleSoup) -> f64 {
    soup.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| soup.positions[i as usize]);
            a.dot(b.cross(c))
        })
        .sum()
}

fn tetra_builder() -> (GltfBuilder, usize) {
    let (points, indices) = tetrahedron();
    let mut b = GltfBuilder::default();
    let pos = b.add_positions(&points);
    let idx = b.add_indices_u32(&indices);
    let mesh = b.add_mesh(pos, Some(idx), None);
    (b, mesh)
}

#[test]
fn nested_transforms_compose_parent_times_child() {
    let (mut b, mesh) = tetra_builder();
    // child: scale 2 then translate x by 1; parent: rotate 90 degrees about z, translate z by 5.
    let child = b.add_node(&format!(
        r#""mesh":{mesh},"scale":[2,2,2],"translation":[1,0,0]"#
    ));
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let parent = b.add_node(&format!(
        r#""children":[{child}],"rotation":[0,0,{s:?},{s:?}],"translation":[0,0,5]"#
    ));
    b.add_scene(&[parent]);
    let soup = read_named("nested.glb", &b.glb()).unwrap();
    let (points, _) = tetrahedron();
    assert_eq!(soup.positions.len(), 4);
    for (p, q) in points.iter().zip(&soup.positions) {
        let local = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * 2.0 + DVec3::X;
        // Rotation by +90 degrees about z: (x, y) -> (-y, x).
        let want = DVec3::new(-local.y, local.x, local.z + 5.0);
        assert!((want - *q).length() < 1e-6, "{q} != {want}");
    }
    assert!(signed_volume6(&soup) > 0.0);
}

#[test]
fn negative_scale_mirrors_and_flips_the_winding() {
    let (mut b, mesh) = tetra_builder();
    let plain = b.add_node(&format!(r#""mesh":{mesh}"#));
    let mirrored = b.add_node(&format!(r#""mesh":{mesh},"scale":[-1,1,1]"#));
    b.add_scene(&[plain, mirrored]);
    let soup = read_named("mirror.gltf", &b.gltf_embedded()).unwrap();
    assert_eq!(soup.positions.len(), 8);
    assert_eq!(soup.triangles.len(), 8);
    for i in 0..4 {
        let p = soup.positions[i];
        assert_eq!(soup.positions[i + 4], DVec3::new(-p.x, p.y, p.z));
    }
    for t in 0..4 {
        let [a, b, c] = soup.triangles[t];
        assert_eq!(soup.triangles[t + 4], [a + 4, c + 4, b + 4]);
    }
    // Both copies stay outward-facing: the mirrored one adds the same positive volume.
    let plain_only = TriangleSoup::new(soup.positions.clone(), soup.triangles[..4].to_vec());
    assert!((signed_volume6(&soup) - 2.0 * signed_volume6(&plain_only)).abs() < 1e-12);
}

#[test]
fn a_primitive_without_indices_uses_its_vertices_in_order() {
    let (points, indices) = tetrahedron();
    let unrolled: Vec<[f32; 3]> = indices.iter().map(|&i| points[i as usize]).collect();
    let mut b = GltfBuilder::default();
    let pos = b.add_positions(&unrolled);
    let mesh = b.add_mesh(pos, None, None);
    let node = b.add_node(&format!(r#""mesh":{mesh}"#));
    b.add_scene(&[node]);
    let soup = read_gltf(&b.glb(), "x.glb").unwrap();
    assert_eq!(soup.positions.len(), 12);
    assert_eq!(
        soup.triangles,
        vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]]
    );
}

#[test]
fn strips_and_fans_follow_the_spec_winding() {
    let points = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 2.0, 0.0],
    ];
    let mut b = GltfBuilder::default();
    let pos = b.add_positions(&points);
    let idx = b.add_indices_u16(&[0, 1, 2, 3, 4]);
    let strip = b.add_mesh(pos, Some(idx), Some(5));
    let fan = b.add_mesh(pos, Some(idx), Some(6));
    let n1 = b.add_node(&format!(r#""mesh":{strip}"#));
    let n2 = b.add_node(&format!(r#""mesh":{fan}"#));
    b.add_scene(&[n1, n2]);
    let soup = read_gltf(&b.glb(), "x.glb").unwrap();
    assert_eq!(
        soup.triangles,
        vec![
            // strip: (0,1,2), (1,3,2), (2,3,4)
            [0, 1, 2],
            [1, 3, 2],
            [2, 3, 4],
            // fan (second instance, vertices 5..10): (1,2,0), (2,3,0), (3,4,0)
            [6, 7, 5],
            [7, 8, 5],
            [8, 9, 5],
        ]
    );
    // Every strip triangle faces +z, as its first one does.
    for t in &soup.triangles[..3] {
        let [a, b, c] = t.map(|i| soup.positions[i as usize]);
        assert!((b - a).cross(c - a).z > 0.0, "{t:?}");
    }
}

#[test]
fn sparse_accessors_substitute_their_values() {
    let (points, indices) = tetrahedron();
    let mut b = GltfBuilder::default();
    let dense: Vec<u8> = points
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let dense_view = b.add_view(&dense, None);
    let sparse_indices = b.add_view(&3u16.to_le_bytes(), None);
    let value: Vec<u8> = [0.0f32, 0.0, 4.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let sparse_values = b.add_view(&value, None);
    let pos = b.add_accessor_json(&format!(
        r#""bufferView":{dense_view},"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,4],"sparse":{{"count":1,"indices":{{"bufferView":{sparse_indices},"componentType":5123}},"values":{{"bufferView":{sparse_values}}}}}"#
    ));
    let idx = b.add_indices_u32(&indices);
    let mesh = b.add_mesh(pos, Some(idx), None);
    let node = b.add_node(&format!(r#""mesh":{mesh}"#));
    b.add_scene(&[node]);
    let soup = read_gltf(&b.glb(), "x.glb").unwrap();
    assert_eq!(soup.positions[3], DVec3::new(0.0, 0.0, 4.0));
    assert_eq!(soup.positions[1], DVec3::X);
}

#[test]
fn quantized_positions_decode_normalized_and_plain_integers() {
    let mut b = GltfBuilder::default();
    b.extensions.push(("KHR_mesh_quantization".into(), true));
    // Normalized i16 VEC3, padded to 8-byte elements as the extension requires.
    let shorts: [[i16; 4]; 3] = [[0, 0, 0, 0], [32767, 0, 0, 0], [0, -32768, 0, 0]];
    let bytes: Vec<u8> = shorts
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let view = b.add_view(&bytes, Some(8));
    let pos = b.add_accessor_json(&format!(
        r#""bufferView":{view},"componentType":5122,"normalized":true,"count":3,"type":"VEC3","min":[0,-1,0],"max":[1,0,0]"#
    ));
    // Plain u8 VEC3, 4-byte elements.
    let bytes = [0u8, 0, 0, 0, 10, 0, 0, 0, 0, 0, 20, 0];
    let view = b.add_view(&bytes, Some(4));
    let pos2 = b.add_accessor_json(&format!(
        r#""bufferView":{view},"componentType":5121,"count":3,"type":"VEC3","min":[0,0,0],"max":[10,0,20]"#
    ));
    let m1 = b.add_mesh(pos, None, None);
    let m2 = b.add_mesh(pos2, None, None);
    let n1 = b.add_node(&format!(r#""mesh":{m1}"#));
    let n2 = b.add_node(&format!(r#""mesh":{m2}"#));
    b.add_scene(&[n1, n2]);
    let soup = read_gltf(&b.glb(), "q.glb").unwrap();
    assert_eq!(
        soup.positions,
        vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::ZERO,
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 20.0),
        ]
    );
}

#[test]
fn external_buffers_are_read_beside_the_file() {
    let (mut b, mesh) = tetra_builder();
    let node = b.add_node(&format!(r#""mesh":{mesh}"#));
    b.add_scene(&[node]);
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("data")).unwrap();
    std::fs::write(dir.path().join("data/my buffer.bin"), &b.bin).unwrap();
    let path = dir.path().join("scene.gltf");
    std::fs::write(&path, b.json(Some("data/my%20buffer.bin"))).unwrap();
    let soup = read_mesh(&path).unwrap();
    assert_eq!(soup.triangles.len(), 4);
    assert_eq!(soup, read_gltf(&b.glb(), "same.glb").unwrap());

    // In memory there is no folder to read it from; outside the folder is refused.
    let message = read_gltf(b.json(Some("data/my%20buffer.bin")).as_bytes(), "mem.gltf")
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("read the .gltf from its path"),
        "{message}"
    );
    std::fs::write(&path, b.json(Some("../secret.bin"))).unwrap();
    let message = read_mesh(&path).unwrap_err().to_string();
    assert!(message.contains("not a plain path inside"), "{message}");
}

#[test]
fn the_default_scene_is_read_or_scene_zero() {
    let (mut b, mesh) = tetra_builder();
    let near = b.add_node(&format!(r#""mesh":{mesh}"#));
    let far = b.add_node(&format!(r#""mesh":{mesh},"translation":[100,0,0]"#));
    b.add_scene(&[near]);
    b.add_scene(&[far]);
    let first = read_gltf(&b.glb(), "x.glb").unwrap();
    assert_eq!(first.positions[1], DVec3::X);
    b.scene = Some(1);
    let marked = read_gltf(&b.glb(), "x.glb").unwrap();
    assert_eq!(marked.positions[1], DVec3::new(101.0, 0.0, 0.0));
}

/// Asserts that reading `bytes` fails with a one-line message containing `want`.
fn assert_refused(bytes: &[u8], want: &str) {
    let message = match read_gltf(bytes, "bad.glb") {
        Ok(soup) => panic!("accepted {} triangles", soup.triangles.len()),
        Err(e) => e.to_string(),
    };
    assert!(message.starts_with("bad.glb"), "{message}");
    assert!(message.contains(want), "{message:?} lacks {want:?}");
    assert!(!message.contains('\n'), "{message:?}");
}

#[test]
fn points_lines_and_compressed_files_are_refused_by_name() {
    let (points, _) = tetrahedron();
    for (mode, word) in [(0, "points"), (1, "lines"), (2, "lines"), (3, "lines")] {
        let mut b = GltfBuilder::default();
        let pos = b.add_positions(&points);
        let mesh = b.add_mesh(pos, None, Some(mode));
        let node = b.add_node(&format!(r#""mesh":{mesh}"#));
        b.add_scene(&[node]);
        assert_refused(&b.glb(), &format!("draws {word}"));
    }
    for (ext, what) in [
        ("KHR_draco_mesh_compression", "Draco"),
        ("EXT_meshopt_compression", "meshopt"),
    ] {
        let (mut b, mesh) = tetra_builder();
        let node = b.add_node(&format!(r#""mesh":{mesh}"#));
        b.add_scene(&[node]);
        b.extensions.push((ext.into(), true));
        assert_refused(&b.glb(), &format!("needs {what} decompression ({ext})"));
    }
}

#[test]
fn broken_documents_are_refused_with_one_line() {
    let (points, _) = tetrahedron();
    // An index past the positions.
    let mut b = GltfBuilder::default();
    let pos = b.add_positions(&points);
    let idx = b.add_indices_u32(&[0, 1, 4]);
    let mesh = b.add_mesh(pos, Some(idx), None);
    let node = b.add_node(&format!(r#""mesh":{mesh}"#));
    b.add_scene(&[node]);
    assert_refused(&b.glb(), "index 4 out of range");

    // An accessor longer than its view.
    let mut b = GltfBuilder::default();
    let view = b.add_view(&[0u8; 24], None);
    let (min, max) = bounds(&points);
    let pos = b.add_accessor_json(&format!(
        r#""bufferView":{view},"componentType":5126,"count":4,"type":"VEC3","min":{min},"max":{max}"#
    ));
    let mesh = b.add_mesh(pos, None, None);
    let node = b.add_node(&format!(r#""mesh":{mesh}"#));
    b.add_scene(&[node]);
    assert_refused(&b.glb(), "runs past the end of buffer view");

    // A POSITION accessor that does not exist (the crate's validator would index it).
    let mut b = GltfBuilder::default();
    let mesh = b.add_mesh(99, None, None);
    let node = b.add_node(&format!(r#""mesh":{mesh}"#));
    b.add_scene(&[node]);
    assert_refused(&b.glb(), "POSITION accessor 99 does not exist");

    // A node that is its own child.
    let (mut b, mesh) = tetra_builder();
    let node = b.add_node(&format!(r#""mesh":{mesh},"children":[0]"#));
    b.add_scene(&[node]);
    assert_refused(&b.glb(), "cycle");

    // A NaN coordinate.
    let mut b = GltfBuilder::default();
    let pos = b.add_positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [f32::NAN, 1.0, 0.0]]);
    let mesh = b.add_mesh(pos, None, None);
    let node = b.add_node(&format!(r#""mesh":{mesh}"#));
    b.add_scene(&[node]);
    let message = read_gltf(&b.glb(), "bad.glb").unwrap_err().to_string();
    assert!(message.starts_with("bad.glb"), "{message}");

    // No scene, a scene without meshes, and not glTF at all.
    let (b, _) = tetra_builder();
    assert_refused(&b.glb(), "no scene");
    let mut b = GltfBuilder::default();
    let node = b.add_node("");
    b.add_scene(&[node]);
    assert_refused(&b.glb(), "no triangles");
    assert_refused(b"solid x\nendsolid x\n", "not a glTF file");
}

#[test]
fn gltf_is_read_but_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let (points, _) = tetrahedron();
    let soup = TriangleSoup::new(
        points
            .iter()
            .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect(),
        vec![[0, 1, 2]],
    );
    let path = dir.path().join("out.glb");
    let message = roar_io::write_mesh(&path, &soup).unwrap_err().to_string();
    assert!(message.contains("does not write it"), "{message}");
    assert!(!path.exists());
}
