//! glTF 2.0 input (`.gltf` with its buffers, `.glb`), through the `gltf` crate.
//!
//! The `gltf` crate parses the JSON and the GLB container and validates the document (every
//! index in range, required fields present). Accessor data is decoded here, with checked
//! arithmetic, so a file whose accessors run past their buffers gives an error instead of a
//! panic or garbage.
//!
//! What is read: every mesh primitive instanced by the nodes of the default scene (scene 0 when
//! the file marks none), with the nodes' transforms composed in f64 from the file's f32 values
//! and applied to the positions. A transform with a negative determinant (an odd number of
//! negative scales) mirrors the primitive, so its triangles' winding is flipped to keep their
//! orientation. Triangles, triangle strips and triangle fans are read; indexed or not; plain,
//! sparse and `KHR_mesh_quantization` (integer, optionally normalized) position accessors.
//! Points and lines are refused with a message, as are files that need Draco or meshopt
//! decompression. Vertices are numbered primitive instance by primitive instance, in scene
//! order (depth first, children in file order); nothing is welded.

use std::path::Path;

use base64::Engine as _;
use glam::{DMat4, DQuat, DVec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use crate::error::IoError;
use crate::soup::TriangleSoup;

/// Extensions whose data this reader cannot decode, with what they are, refused by name.
const COMPRESSION_EXTENSIONS: [(&str, &str); 3] = [
    ("KHR_draco_mesh_compression", "Draco"),
    ("EXT_meshopt_compression", "meshopt"),
    ("KHR_meshopt_compression", "meshopt"),
];

/// Node instances visited at most (a scene whose nodes share children could otherwise make the
/// traversal exponential).
const MAX_NODE_INSTANCES: usize = 1 << 20;

/// Reads a `.gltf` or `.glb` file; a `.gltf`'s external buffers are read relative to its folder.
///
/// Errors: the file or a buffer cannot be read, the document is malformed or invalid, a buffer
/// URI leaves the file's folder, an accessor runs past its buffer, a primitive draws points or
/// lines, the file needs Draco or meshopt decompression, or the scene holds no triangle.
pub fn read_gltf_file(path: &Path) -> Result<TriangleSoup, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    read_gltf_in(&bytes, &path.display().to_string(), path.parent())
}

/// Parses a self-contained glTF already in memory (a `.glb`, or a `.gltf` whose buffers are
/// `data:` URIs); `name` labels errors. A buffer in an external file is an error: use
/// [`read_gltf_file`] for those.
pub fn read_gltf(bytes: &[u8], name: &str) -> Result<TriangleSoup, IoError> {
    read_gltf_in(bytes, name, None)
}

fn read_gltf_in(bytes: &[u8], name: &str, folder: Option<&Path>) -> Result<TriangleSoup, IoError> {
    let err = |message: String| IoError::in_file(name, message);
    let gltf = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| err(format!("not a glTF file: {}", one_line(&e.to_string()))))?;
    let blob = gltf.blob;
    let mut json = gltf.document.into_json();
    for ext in json.extensions_required.iter().chain(&json.extensions_used) {
        if let Some((_, what)) = COMPRESSION_EXTENSIONS.iter().find(|(n, _)| n == ext) {
            let required = json.extensions_required.contains(ext);
            if required {
                return Err(err(format!(
                    "needs {what} decompression ({ext}), which roar does not read; \
                     export the file without compression"
                )));
            }
        }
    }
    // KHR_mesh_quantization only widens the accessor types allowed for positions, which the
    // decoder below handles; the crate's validator refuses every extension it does not know.
    json.extensions_required
        .retain(|e| e.as_str() != "KHR_mesh_quantization");
    // The crate's validator indexes the POSITION accessor before checking the index is in
    // range (gltf-json 1.4.1, mesh.rs), so a broken index would panic there: check it first.
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive.attributes.iter().find_map(|(semantic, index)| {
                matches!(
                    semantic,
                    gltf::json::validation::Checked::Valid(gltf::Semantic::Positions)
                )
                .then_some(index.value())
            });
            if let Some(index) = position
                && index >= json.accessors.len()
            {
                return Err(err(format!(
                    "mesh {m} primitive {p}: POSITION accessor {index} does not exist"
                )));
            }
        }
    }
    let document = gltf::Document::from_json(json)
        .map_err(|e| err(format!("invalid glTF: {}", one_line(&e.to_string()))))?;

    let buffers = document
        .buffers()
        .map(|buffer| load_buffer(&buffer, blob.as_deref(), folder, name))
        .collect::<Result<Vec<_>, _>>()?;

    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| err("the file has no scene".to_string()))?;

    let mut soup = TriangleSoup::default();
    let mut visited = 0usize;
    let mut ancestors = Vec::new();
    for node in scene.nodes() {
        add_node(
            &node,
            DMat4::IDENTITY,
            &buffers,
            &mut soup,
            &mut ancestors,
            &mut visited,
            name,
        )?;
    }
    if soup.triangles.is_empty() {
        return Err(err("the scene has no triangles".to_string()));
    }
    soup.validate()
        .map_err(|defect| err(format!("invalid mesh: {defect}")))?;
    Ok(soup)
}

/// The first line of a possibly multi-line message from the `gltf` crate.
fn one_line(message: &str) -> String {
    message
        .lines()
        .next()
        .unwrap_or_default()
        .trim()
        .to_string()
}

/// The bytes of one buffer: the GLB's binary chunk, a base64 `data:` URI, or a file beside the
/// `.gltf` (relative path, no `..`, no absolute path, no other URI scheme).
fn load_buffer(
    buffer: &gltf::Buffer<'_>,
    blob: Option<&[u8]>,
    folder: Option<&Path>,
    name: &str,
) -> Result<Vec<u8>, IoError> {
    let index = buffer.index();
    let err = |message: String| IoError::at_element(name, "buffer", index, message);
    let bytes = match buffer.source() {
        gltf::buffer::Source::Bin => blob
            .ok_or_else(|| err("refers to the binary chunk, but the file has none".to_string()))?
            .to_vec(),
        gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
            let (_, data) = uri
                .split_once(";base64,")
                .ok_or_else(|| err("data URI is not base64".to_string()))?;
            base64::engine::general_purpose::STANDARD
                .decode(data)
                .map_err(|e| err(format!("bad base64 data: {e}")))?
        }
        gltf::buffer::Source::Uri(uri) => {
            let relative = percent_decode(uri);
            let path = Path::new(&relative);
            let escapes = path.is_absolute()
                || relative.contains("://")
                || path
                    .components()
                    .any(|c| !matches!(c, std::path::Component::Normal(_)));
            if escapes {
                return Err(err(format!(
                    "buffer URI {uri:?} is not a plain path inside the file's folder"
                )));
            }
            let folder = folder.ok_or_else(|| {
                err(format!(
                    "buffer {uri:?} is an external file; read the .gltf from its path"
                ))
            })?;
            let full = folder.join(path);
            std::fs::read(&full).map_err(|source| IoError::Os { path: full, source })?
        }
    };
    if bytes.len() < buffer.length() {
        return Err(err(format!(
            "has {} bytes, the file says {}",
            bytes.len(),
            buffer.length()
        )));
    }
    Ok(bytes)
}

/// Decodes `%XX` escapes of a URI reference (glTF URIs are percent-encoded).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && let (Some(h), Some(l)) = (
                bytes.get(i + 1).and_then(|&b| hex(b)),
                bytes.get(i + 2).and_then(|&b| hex(b)),
            )
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The node's local transform in f64, composed from the file's f32 values.
fn local_transform(node: &gltf::Node<'_>) -> DMat4 {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|col| col.map(f64::from)))
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let [x, y, z, w] = rotation.map(f64::from);
            // glTF promises unit quaternions; normalizing keeps a sloppy file's rotation a
            // rotation (a zero quaternion stays the identity).
            let q = DQuat::from_xyzw(x, y, z, w);
            let q = if q.length_squared() > 0.0 {
                q.normalize()
            } else {
                DQuat::IDENTITY
            };
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                q,
                DVec3::from_array(translation.map(f64::from)),
            )
        }
    }
}

/// Adds the node's mesh (under `parent * local`) and then its children, depth first.
fn add_node(
    node: &gltf::Node<'_>,
    parent: DMat4,
    buffers: &[Vec<u8>],
    soup: &mut TriangleSoup,
    ancestors: &mut Vec<usize>,
    visited: &mut usize,
    name: &str,
) -> Result<(), IoError> {
    let index = node.index();
    if ancestors.contains(&index) {
        return Err(IoError::at_element(
            name,
            "node",
            index,
            "is its own ancestor (the node hierarchy has a cycle)",
        ));
    }
    *visited += 1;
    if *visited > MAX_NODE_INSTANCES {
        return Err(IoError::in_file(
            name,
            format!("the scene instances more than {MAX_NODE_INSTANCES} nodes"),
        ));
    }
    let world = parent * local_transform(node);
    if let Some(mesh) = node.mesh() {
        for primitive in mesh.primitives() {
            add_primitive(&primitive, mesh.index(), world, buffers, soup, name)?;
        }
    }
    ancestors.push(index);
    for child in node.children() {
        add_node(&child, world, buffers, soup, ancestors, visited, name)?;
    }
    ancestors.pop();
    Ok(())
}

fn add_primitive(
    primitive: &gltf::Primitive<'_>,
    mesh: usize,
    world: DMat4,
    buffers: &[Vec<u8>],
    soup: &mut TriangleSoup,
    name: &str,
) -> Result<(), IoError> {
    let err = |message: String| {
        IoError::in_file(
            name,
            format!("mesh {mesh} primitive {}: {message}", primitive.index()),
        )
    };
    let mode = primitive.mode();
    match mode {
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => {}
        Mode::Points => return Err(err("draws points; roar reads triangles only".into())),
        Mode::Lines | Mode::LineLoop | Mode::LineStrip => {
            return Err(err("draws lines; roar reads triangles only".into()));
        }
    }
    let accessor = primitive
        .get(&gltf::Semantic::Positions)
        .ok_or_else(|| err("has no POSITION attribute".into()))?;
    if accessor.dimensions() != Dimensions::Vec3 {
        return Err(err("POSITION is not a 3-vector".into()));
    }
    let local = read_accessor(&accessor, buffers).map_err(|m| err(format!("POSITION {m}")))?;
    let n_local = local.len() / 3;
    let corners: Vec<u32> = match primitive.indices() {
        Some(indices) => {
            if indices.dimensions() != Dimensions::Scalar
                || !matches!(
                    indices.data_type(),
                    DataType::U8 | DataType::U16 | DataType::U32
                )
            {
                return Err(err("indices are not unsigned integer scalars".into()));
            }
            let values =
                read_accessor(&indices, buffers).map_err(|m| err(format!("indices {m}")))?;
            let mut corners = Vec::with_capacity(values.len());
            for v in values {
                // Integer accessors decode exactly into f64 (at most u32).
                let i = v as u64;
                if i >= n_local as u64 {
                    return Err(err(format!(
                        "index {i} out of range (POSITION has {n_local} vertices)"
                    )));
                }
                corners.push(i as u32);
            }
            corners
        }
        None => (0..n_local as u32).collect(),
    };

    let base = soup.positions.len();
    if base + n_local > u32::MAX as usize {
        return Err(err("the scene has more than 2^32 vertices".into()));
    }
    for p in local.chunks_exact(3) {
        soup.positions
            .push(world.transform_point3(DVec3::new(p[0], p[1], p[2])));
    }
    let mirrored = world.determinant() < 0.0;
    let mut push = |a: u32, b: u32, c: u32| {
        let [a, b, c] = [a, b, c].map(|i| i + base as u32);
        soup.triangles
            .push(if mirrored { [a, c, b] } else { [a, b, c] });
    };
    let k = corners.len();
    match mode {
        Mode::Triangles => {
            for t in corners.chunks_exact(3) {
                push(t[0], t[1], t[2]);
            }
        }
        // glTF 2.0 specification, section 3.7.2.1:
        // strip triangle i is (v_i, v_{i+1+i%2}, v_{i+2-i%2}).
        Mode::TriangleStrip => {
            for i in 0..k.saturating_sub(2) {
                let odd = i % 2;
                push(corners[i], corners[i + 1 + odd], corners[i + 2 - odd]);
            }
        }
        // glTF 2.0 specification, section 3.7.2.1: fan triangle i is (v_{i+1}, v_{i+2}, v_0).
        Mode::TriangleFan => {
            for i in 0..k.saturating_sub(2) {
                push(corners[i + 1], corners[i + 2], corners[0]);
            }
        }
        _ => unreachable!("points and lines were refused above"),
    }
    Ok(())
}

/// Decodes an accessor into `count * components` f64 values, in element order: dense data from
/// its buffer view (zeros when it has none), then the sparse substitutions. Integer components
/// are converted exactly, or mapped to [-1, 1] / [0, 1] when the accessor is normalized.
fn read_accessor(accessor: &gltf::Accessor<'_>, buffers: &[Vec<u8>]) -> Result<Vec<f64>, String> {
    let n = accessor.dimensions().multiplicity();
    let data_type = accessor.data_type();
    let normalized = accessor.normalized();
    let count = accessor.count();
    let total = count
        .checked_mul(n)
        .ok_or_else(|| "element count overflows".to_string())?;
    let mut values = vec![0.0; total];
    if let Some(view) = accessor.view() {
        let elements = view_elements(&view, accessor.offset(), count, n, data_type, buffers)?;
        for (e, at) in elements.into_iter().enumerate() {
            for c in 0..n {
                values[e * n + c] = decode(
                    &buffers[view.buffer().index()],
                    at + c * data_type.size(),
                    data_type,
                    normalized,
                );
            }
        }
    }
    if let Some(sparse) = accessor.sparse() {
        let m = sparse.count();
        let indices = sparse.indices();
        let index_type = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let index_view = indices.view();
        let index_at = view_elements(&index_view, indices.offset(), m, 1, index_type, buffers)?;
        let value_view = sparse.values().view();
        let value_at = view_elements(
            &value_view,
            sparse.values().offset(),
            m,
            n,
            data_type,
            buffers,
        )?;
        for (&ia, &va) in index_at.iter().zip(&value_at) {
            let target =
                decode(&buffers[index_view.buffer().index()], ia, index_type, false) as usize;
            if target >= count {
                return Err(format!(
                    "sparse index {target} out of range (accessor has {count} elements)"
                ));
            }
            for c in 0..n {
                values[target * n + c] = decode(
                    &buffers[value_view.buffer().index()],
                    va + c * data_type.size(),
                    data_type,
                    normalized,
                );
            }
        }
    }
    if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!("element {} is NaN or infinite", bad / n));
    }
    Ok(values)
}

/// The byte offset, in the view's buffer, of each of `count` elements of `n` components of
/// `data_type` stored in `view` from `offset`; an error if any byte lies outside the view or
/// the buffer.
fn view_elements(
    view: &gltf::buffer::View<'_>,
    offset: usize,
    count: usize,
    n: usize,
    data_type: DataType,
    buffers: &[Vec<u8>],
) -> Result<Vec<usize>, String> {
    let element = n * data_type.size();
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "byte stride {stride} is smaller than its {element}-byte elements"
        ));
    }
    let buffer_len = buffers[view.buffer().index()].len();
    let overrun = || format!("runs past the end of buffer view {}", view.index());
    if count > 0 {
        let end = (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(offset))
            .and_then(|x| x.checked_add(element))
            .ok_or_else(overrun)?;
        let view_end = view
            .offset()
            .checked_add(view.length())
            .ok_or_else(overrun)?;
        if end > view.length() || view_end > buffer_len {
            return Err(overrun());
        }
    }
    Ok((0..count)
        .map(|i| view.offset() + offset + i * stride)
        .collect())
}

/// One little-endian component at `at` (in bounds: checked by [`view_elements`]).
fn decode(buffer: &[u8], at: usize, data_type: DataType, normalized: bool) -> f64 {
    let b = &buffer[at..at + data_type.size()];
    match data_type {
        DataType::I8 => {
            let v = f64::from(b[0] as i8);
            if normalized { (v / 127.0).max(-1.0) } else { v }
        }
        DataType::U8 => {
            let v = f64::from(b[0]);
            if normalized { v / 255.0 } else { v }
        }
        DataType::I16 => {
            let v = f64::from(i16::from_le_bytes([b[0], b[1]]));
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        DataType::U16 => {
            let v = f64::from(u16::from_le_bytes([b[0], b[1]]));
            if normalized { v / 65535.0 } else { v }
        }
        DataType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    }
}
