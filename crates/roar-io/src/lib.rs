//! # roar-io
//!
//! [`TriangleSoup`] (plain buffers in which anything goes) and readers and writers for the mesh
//! formats roar speaks: OBJ, PLY (ASCII, binary little and big endian), STL (ASCII and binary)
//! and OFF; glTF 2.0 input (`.gltf`, `.glb`; see [`read_gltf_file`]); range scans (PLY range
//! images, [`RangeGrid`], read as their patch anywhere a mesh is; Stanford `.conf` scan sets,
//! [`read_scan_set`]); image dumps (PNG, EXR); atomic writes.
//!
//! ## Naming
//!
//! * `read_mesh(path)` / `write_mesh(path, soup)` pick the format from the extension
//!   (case-insensitive: `obj`, `ply`, `stl`, `off`; `gltf` and `glb` for reading only).
//! * `read_<fmt>(bytes, name)` parses a file already in memory; `name` only labels errors.
//! * `write_<fmt>(writer, soup[, encoding])` streams a soup into any writer.
//!
//! ## Promises
//!
//! * A successful read returns a soup that passes [`TriangleSoup::validate`]: at least one
//!   triangle, finite coordinates, indices in range. Polygons are triangulated in their plane by
//!   ear clipping (in one place for every reader: convex ones stay fans, concave ones get no
//!   overlapping triangles) and counted in [`TriangleSoup::n_polygons`], those that could not be
//!   triangulated cleanly in [`TriangleSoup::n_polygons_unclean`]. Faces of fewer than 3
//!   corners bound no surface: they are skipped and counted in
//!   [`TriangleSoup::n_faces_skipped`], not refused. Degenerate triangles (repeated indices,
//!   zero area) are kept. Vertices are numbered as in the file (OBJ: globally across groups);
//!   nothing is welded unless you call [`TriangleSoup::welded`].
//! * Malformed input never panics: it gives an [`IoError`] whose one-line message names the file
//!   and, where it applies, the line (`bunny.obj:1234: ...`) or element (`x.stl: triangle 7: ...`).
//! * Written coordinates read back bit-identical in OBJ, OFF, PLY and ASCII STL (shortest
//!   round-trip decimal formatting or binary f64). Binary STL stores f32 and cannot round-trip
//!   arbitrary f64.
//! * Files are written atomically ([`atomic_write`]): on error no partial output is left.

mod atomic;
mod error;
mod gltf;
mod image_dump;
mod obj;
mod off;
mod ply;
mod point_scan;
mod polygon;
mod range_grid;
mod scan_set;
mod soup;
mod stl;
mod text;

use std::path::Path;

pub use atomic::{
    FileContent, atomic_write, atomic_write_all, check_writable, remove_temporary_files,
    write_destination,
};
pub use error::{IoError, Location};
pub use gltf::{read_gltf, read_gltf_file};
pub use image_dump::{write_exr_rgba, write_png_rgba8};
pub use obj::{read_obj, write_obj};
pub use off::{read_off, write_off};
pub use ply::{PlyEncoding, read_ply, read_range_grid, write_ply};
pub use point_scan::point_scan_patch;
pub use polygon::{MAX_EAR_CLIPPING_CORNERS, PLANARITY_TOLERANCE, triangulate_polygon};
pub use range_grid::{PatchOptions, PatchStats, RangeGrid, SCANNER_VIEW};
pub use scan_set::{
    ScanPose, ScanSet, is_scan_set, read_range_grid_file, read_scan_patch_file, read_scan_set,
};
pub use soup::{SoupDefect, TriangleSoup};
pub use stl::{StlEncoding, read_stl, write_stl};

/// The mesh file formats, as chosen by a file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront `.obj`.
    Obj,
    /// Stanford `.ply`.
    Ply,
    /// `.stl`.
    Stl,
    /// `.off`.
    Off,
    /// glTF 2.0, `.gltf` (JSON with its buffers) or `.glb` (binary); read only.
    Gltf,
}

impl MeshFormat {
    /// The format named by `path`'s extension, compared case-insensitively (`.STL` is STL).
    pub fn from_path(path: &Path) -> Result<MeshFormat, IoError> {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default();
        match extension.to_ascii_lowercase().as_str() {
            "obj" => Ok(MeshFormat::Obj),
            "ply" => Ok(MeshFormat::Ply),
            "stl" => Ok(MeshFormat::Stl),
            "off" => Ok(MeshFormat::Off),
            "gltf" | "glb" => Ok(MeshFormat::Gltf),
            _ => Err(IoError::UnknownFormat {
                path: path.to_path_buf(),
                extension,
            }),
        }
    }

    /// The format named by `path`'s extension, refusing formats roar reads but does not write
    /// (glTF), so a command can check its output path before any work.
    pub fn for_writing(path: &Path) -> Result<MeshFormat, IoError> {
        match MeshFormat::from_path(path)? {
            MeshFormat::Gltf => Err(IoError::InvalidInput {
                path: path.to_path_buf(),
                message: "roar reads glTF but does not write it (write obj, ply, stl or off)"
                    .to_string(),
            }),
            format => Ok(format),
        }
    }
}

/// How [`write_mesh_with`] encodes formats that have several encodings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WriteOptions {
    /// PLY encoding (default binary little endian: compact, bit-identical f64).
    pub ply: PlyEncoding,
    /// STL encoding (default binary: compact, but f32 only).
    pub stl: StlEncoding,
}

/// Reads a mesh file, choosing the reader by extension (see [`MeshFormat::from_path`]).
///
/// Errors: unknown extension, the file cannot be read, or its content is malformed (see the
/// per-format readers); every message names the file. A `.gltf`'s external buffers are read
/// from its folder.
pub fn read_mesh(path: &Path) -> Result<TriangleSoup, IoError> {
    let format = MeshFormat::from_path(path)?;
    if format == MeshFormat::Gltf {
        return read_gltf_file(path);
    }
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    read_mesh_bytes(&bytes, &path.display().to_string(), format)
}

/// Parses a mesh already in memory in the given format; `name` labels errors. glTF must be
/// self-contained here (`.glb` or `data:` buffers, see [`read_gltf`]).
pub fn read_mesh_bytes(
    bytes: &[u8],
    name: &str,
    format: MeshFormat,
) -> Result<TriangleSoup, IoError> {
    match format {
        MeshFormat::Obj => read_obj(bytes, name),
        MeshFormat::Ply => read_ply(bytes, name),
        MeshFormat::Stl => read_stl(bytes, name),
        MeshFormat::Off => read_off(bytes, name),
        MeshFormat::Gltf => read_gltf(bytes, name),
    }
}

/// Writes `soup` atomically in the format named by `path`'s extension, with default encodings
/// (PLY binary little endian, STL binary). Same as [`write_mesh_with`] with default options.
pub fn write_mesh(path: &Path, soup: &TriangleSoup) -> Result<(), IoError> {
    write_mesh_with(path, soup, &WriteOptions::default())
}

/// Writes `soup` atomically in the format named by `path`'s extension.
///
/// Errors (and nothing is written): unknown extension, an invalid soup (see
/// [`TriangleSoup::validate`]: no triangles, NaN/inf, indices out of range), or an OS failure.
pub fn write_mesh_with(
    path: &Path,
    soup: &TriangleSoup,
    options: &WriteOptions,
) -> Result<(), IoError> {
    write_mesh_and_files(path, soup, options, &[])
}

/// Writes `soup` (as [`write_mesh_with`]) and the byte files `others` all or nothing
/// ([`atomic_write_all`]): a mesh and its report, where a report that cannot be written must not
/// leave the mesh behind.
pub fn write_mesh_and_files(
    path: &Path,
    soup: &TriangleSoup,
    options: &WriteOptions,
    others: &[(&Path, &[u8])],
) -> Result<(), IoError> {
    let format = MeshFormat::for_writing(path)?;
    soup.validate().map_err(|defect| IoError::InvalidInput {
        path: path.to_path_buf(),
        message: format!("cannot write an invalid mesh: {defect}"),
    })?;
    let mut files: Vec<(&Path, FileContent<'_>)> = vec![(
        path,
        Box::new(move |w: &mut dyn std::io::Write| match format {
            MeshFormat::Obj => write_obj(w, soup),
            MeshFormat::Ply => write_ply(w, soup, options.ply),
            MeshFormat::Stl => write_stl(w, soup, options.stl),
            MeshFormat::Off => write_off(w, soup),
            MeshFormat::Gltf => Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "roar does not write glTF",
            )),
        }),
    )];
    for &(other, bytes) in others {
        files.push((
            other,
            Box::new(move |w: &mut dyn std::io::Write| w.write_all(bytes)),
        ));
    }
    atomic_write_all(files)
}
