//! A tiny glTF 2.0 writer for tests: one binary buffer, accessors appended one by one, and the
//! document as JSON (buffer as a `data:` URI or an external file) or as a `.glb`.

use base64::Engine as _;

/// A glTF document under construction; every `add_*` returns the new object's index.
#[derive(Default)]
pub struct GltfBuilder {
    /// The one buffer's bytes.
    pub bin: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
    /// Mesh objects as JSON (`{"primitives": [...]}`).
    pub meshes: Vec<String>,
    /// Node objects as JSON.
    pub nodes: Vec<String>,
    /// Scene objects as JSON.
    pub scenes: Vec<String>,
    /// The `scene` property, if any.
    pub scene: Option<usize>,
    /// `extensionsUsed` (and `extensionsRequired` when the flag is set).
    pub extensions: Vec<(String, bool)>,
}

impl GltfBuilder {
    /// Appends `bytes` as a new buffer view (4-byte aligned), with an optional byte stride.
    pub fn add_view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let stride = stride
            .map(|s| format!(r#","byteStride":{s}"#))
            .unwrap_or_default();
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}{stride}}}"#,
            self.bin.len(),
            bytes.len()
        ));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// Appends an accessor given as the JSON object's fields (without braces).
    pub fn add_accessor_json(&mut self, fields: &str) -> usize {
        self.accessors.push(format!("{{{fields}}}"));
        self.accessors.len() - 1
    }

    /// A float VEC3 position accessor (with the `min`/`max` glTF requires).
    pub fn add_positions(&mut self, points: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = points
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.add_view(&bytes, None);
        let (min, max) = bounds(points);
        self.add_accessor_json(&format!(
            r#""bufferView":{view},"componentType":5126,"count":{},"type":"VEC3","min":{min},"max":{max}"#,
            points.len()
        ))
    }

    /// An unsigned-int index accessor (componentType 5125).
    pub fn add_indices_u32(&mut self, indices: &[u32]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.add_view(&bytes, None);
        self.add_accessor_json(&format!(
            r#""bufferView":{view},"componentType":5125,"count":{},"type":"SCALAR""#,
            indices.len()
        ))
    }

    /// An unsigned-short index accessor (componentType 5123).
    pub fn add_indices_u16(&mut self, indices: &[u16]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.add_view(&bytes, None);
        self.add_accessor_json(&format!(
            r#""bufferView":{view},"componentType":5123,"count":{},"type":"SCALAR""#,
            indices.len()
        ))
    }

    /// A mesh with one primitive; `indices` and `mode` are optional (mode 4 = triangles).
    pub fn add_mesh(
        &mut self,
        positions: usize,
        indices: Option<usize>,
        mode: Option<u32>,
    ) -> usize {
        let indices = indices
            .map(|i| format!(r#","indices":{i}"#))
            .unwrap_or_default();
        let mode = mode.map(|m| format!(r#","mode":{m}"#)).unwrap_or_default();
        self.meshes.push(format!(
            r#"{{"primitives":[{{"attributes":{{"POSITION":{positions}}}{indices}{mode}}}]}}"#
        ));
        self.meshes.len() - 1
    }

    /// A node given as the JSON object's fields (without braces), e.g. `"mesh":0,"scale":[-1,1,1]`.
    pub fn add_node(&mut self, fields: &str) -> usize {
        self.nodes.push(format!("{{{fields}}}"));
        self.nodes.len() - 1
    }

    /// A scene with these root nodes.
    pub fn add_scene(&mut self, roots: &[usize]) -> usize {
        let roots: Vec<String> = roots.iter().map(|r| r.to_string()).collect();
        self.scenes
            .push(format!(r#"{{"nodes":[{}]}}"#, roots.join(",")));
        self.scenes.len() - 1
    }

    /// The JSON document; `uri` is the buffer's URI, or `None` for no URI (the GLB chunk).
    pub fn json(&self, uri: Option<&str>) -> String {
        let uri = uri.map(|u| format!(r#","uri":"{u}""#)).unwrap_or_default();
        let scene = self
            .scene
            .map(|s| format!(r#""scene":{s},"#))
            .unwrap_or_default();
        let list = |names: Vec<String>| {
            names
                .iter()
                .map(|n| format!("\"{n}\""))
                .collect::<Vec<_>>()
                .join(",")
        };
        let used = list(self.extensions.iter().map(|(n, _)| n.clone()).collect());
        let required = list(
            self.extensions
                .iter()
                .filter(|(_, r)| *r)
                .map(|(n, _)| n.clone())
                .collect(),
        );
        format!(
            r#"{{"asset":{{"version":"2.0"}},{scene}"extensionsUsed":[{used}],"extensionsRequired":[{required}],"scenes":[{}],"nodes":[{}],"meshes":[{}],"accessors":[{}],"bufferViews":[{}],"buffers":[{{"byteLength":{}{uri}}}]}}"#,
            self.scenes.join(","),
            self.nodes.join(","),
            self.meshes.join(","),
            self.accessors.join(","),
            self.views.join(","),
            self.bin.len(),
        )
    }

    /// A self-contained `.gltf`: the buffer as a base64 `data:` URI.
    pub fn gltf_embedded(&self) -> Vec<u8> {
        let data = base64::engine::general_purpose::STANDARD.encode(&self.bin);
        self.json(Some(&format!(
            "data:application/octet-stream;base64,{data}"
        )))
        .into_bytes()
    }

    /// A `.glb`: header, JSON chunk, BIN chunk (both padded to 4 bytes).
    pub fn glb(&self) -> Vec<u8> {
        let mut json = self.json(None).into_bytes();
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
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
}

/// JSON `min` and `max` arrays of a point list.
pub fn bounds(points: &[[f32; 3]]) -> (String, String) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in points {
        for c in 0..3 {
            min[c] = min[c].min(p[c]);
            max[c] = max[c].max(p[c]);
        }
    }
    let fmt = |v: [f32; 3]| format!("[{:?},{:?},{:?}]", v[0], v[1], v[2]);
    (fmt(min), fmt(max))
}

/// A tetrahedron with outward-facing (counter-clockwise) triangles.
pub fn tetrahedron() -> (Vec<[f32; 3]>, Vec<u32>) {
    (
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
    )
}
