//! PLY (Stanford polygon format): reader for ASCII, binary little endian and binary big endian;
//! writers for all three.
//!
//! The reader parses the header's elements and properties and walks the body element by
//! element, so elements and properties it does not need (colours, confidence, normals, edges,
//! materials, lists included) are skipped correctly. It keeps the `vertex` element's `x y z`
//! (any scalar type) and the `face` element's `vertex_indices` (or `vertex_index`) list (any
//! integer count and index type); polygons are triangulated, faces of fewer than 3 corners are
//! skipped and counted.
//!
//! A range image (`obj_info num_cols C` / `num_rows R` and an `element range_grid` of `C·R`
//! lists holding no index or one vertex index, row-major, the Stanford scans' layout) is read
//! by [`read_range_grid`]; [`read_ply`] turns a file with a range grid and no faces into its
//! patch ([`crate::RangeGrid::patch`] with default options), so one scan is accepted anywhere a
//! mesh is; a file of points alone is an unorganised scan, read as its Delaunay patch
//! ([`crate::point_scan_patch`]).
//!
//! The writers emit `double x, y, z` and `list uchar uint vertex_indices`: binary output
//! round-trips f64 bit for bit, and so does ASCII (shortest round-trip formatting).

use std::io::Write;

use crate::error::{IoError, Location};
use crate::soup::TriangleSoup;
use crate::text::{FanBuilder, parse_f64, parse_i64, show, skipped_note, tokens};

/// The three PLY encodings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlyEncoding {
    /// `format ascii 1.0`.
    Ascii,
    /// `format binary_little_endian 1.0` (the compact default).
    #[default]
    BinaryLittleEndian,
    /// `format binary_big_endian 1.0`.
    BinaryBigEndian,
}

/// A scalar type of the PLY header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// One value read from the body.
#[derive(Debug, Clone, Copy)]
enum Num {
    Int(i64),
    Float(f64),
}

impl Num {
    fn as_f64(self) -> f64 {
        match self {
            Num::Int(i) => i as f64,
            Num::Float(f) => f,
        }
    }

    /// Integer value (header checks guarantee integer types where this is used).
    fn as_i64(self) -> i64 {
        match self {
            Num::Int(i) => i,
            Num::Float(f) => f as i64,
        }
    }
}

#[derive(Debug, Clone)]
enum PropertyKind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    kind: PropertyKind,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
    /// 1-based header line of the `element` declaration (for errors about the element).
    line: usize,
}

#[derive(Debug)]
struct Header {
    encoding: PlyEncoding,
    elements: Vec<Element>,
    /// Byte offset of the body (just after the `end_header` line).
    body: usize,
    /// 1-based line number of the body's first line (for ASCII errors).
    body_line: usize,
    /// `obj_info num_cols` and `obj_info num_rows` (range images), when given.
    grid_size: [Option<usize>; 2],
}

/// What a PLY body holds: its vertices, then its faces or its range grid.
struct PlyBody {
    positions: Vec<glam::DVec3>,
    faces: Option<crate::text::Faces>,
    /// The `range_grid` cells (row-major; `None` where the scanner saw nothing), with the
    /// header's `[num_cols, num_rows]`, when the file has a range grid and no faces.
    grid: Option<(Vec<Option<u32>>, [usize; 2])>,
}

/// Reads a PLY file in any of the three encodings; `file` names it in errors.
///
/// Errors: a malformed header (with its line), a missing `vertex` element or `x y z`, a missing
/// face list, truncated bodies, malformed numbers, NaN/inf coordinates and face indices out of
/// range (with the line for ASCII, the element index for binary), and no triangles. Faces with
/// fewer than 3 corners are skipped and counted in [`TriangleSoup::n_faces_skipped`].
pub fn read_ply(bytes: &[u8], file: &str) -> Result<TriangleSoup, IoError> {
    let body = read_ply_body(bytes, file)?;
    let (cells, [cols, rows]) = match (body.faces, body.grid) {
        (Some(faces), _) => {
            return Ok(faces.into_soup(body.positions));
        }
        (None, Some(grid)) => grid,
        (None, None) => {
            let (patch, _) =
                crate::point_scan_patch(&body.positions, &crate::PatchOptions::default());
            if patch.triangles.is_empty() {
                return Err(IoError::in_file(
                    file,
                    "PLY file has no faces and no range grid, and its points give no triangle \
                     as an unorganised scan",
                ));
            }
            return Ok(patch);
        }
    };
    let grid = crate::RangeGrid {
        cols,
        rows,
        positions: body.positions,
        cells,
    };
    let (patch, _) = grid.patch(&crate::PatchOptions::default());
    if patch.triangles.is_empty() {
        return Err(IoError::in_file(
            file,
            "range grid has no triangle (no two neighbouring samples)",
        ));
    }
    Ok(patch)
}

/// Reads a PLY range image (`obj_info num_cols/num_rows`, `element range_grid`; ASCII or
/// binary, LF or CRLF); `file` names it in errors.
///
/// Errors, besides those of [`read_ply`]: no `range_grid` element, missing or zero
/// `num_cols`/`num_rows`, a cell count other than `num_cols · num_rows` (at the element's header
/// line), a cell with more than one index or an index past the vertex count (at its line).
pub fn read_range_grid(bytes: &[u8], file: &str) -> Result<crate::RangeGrid, IoError> {
    let body = read_ply_body(bytes, file)?;
    let (cells, [cols, rows]) = body
        .grid
        .ok_or_else(|| IoError::in_file(file, "PLY file has no 'range_grid' element"))?;
    Ok(crate::RangeGrid {
        cols,
        rows,
        positions: body.positions,
        cells,
    })
}

/// A scan's patch from a PLY file: its range grid's ([`crate::RangeGrid::patch`]) or, for points
/// alone, the unorganised scan's ([`crate::point_scan_patch`]); a file with faces is not a scan.
pub(crate) fn read_scan_patch(
    bytes: &[u8],
    file: &str,
    options: &crate::PatchOptions,
) -> Result<(TriangleSoup, crate::PatchStats), IoError> {
    let body = read_ply_body(bytes, file)?;
    match (body.faces, body.grid) {
        (Some(_), _) => Err(IoError::in_file(
            file,
            "a scan is a range grid or points alone, but this PLY file has faces",
        )),
        (None, Some((cells, [cols, rows]))) => Ok(crate::RangeGrid {
            cols,
            rows,
            positions: body.positions,
            cells,
        }
        .patch(options)),
        (None, None) => Ok(crate::point_scan_patch(&body.positions, options)),
    }
}

fn read_ply_body(bytes: &[u8], file: &str) -> Result<PlyBody, IoError> {
    let header = parse_header(bytes, file)?;
    let body = &bytes[header.body..];
    match header.encoding {
        PlyEncoding::Ascii => read_body(
            &header,
            body.len(),
            file,
            AsciiSource {
                lines: body.split(|&b| b == b'\n'),
                line_no: header.body_line - 1,
                tokens: Vec::new(),
                next: 0,
            },
        ),
        PlyEncoding::BinaryLittleEndian | PlyEncoding::BinaryBigEndian => read_body(
            &header,
            body.len(),
            file,
            BinarySource {
                bytes: body,
                pos: 0,
                big_endian: header.encoding == PlyEncoding::BinaryBigEndian,
            },
        ),
    }
}

fn parse_header(bytes: &[u8], file: &str) -> Result<Header, IoError> {
    let mut pos = 0;
    let mut line_no = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut grid_size = [None, None];
    loop {
        let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err(if line_no == 0 && !bytes.starts_with(b"ply") {
                IoError::in_file(file, "not a PLY file (does not start with 'ply')")
            } else {
                IoError::in_file(
                    file,
                    "PLY header not terminated by 'end_header' (truncated?)",
                )
            });
        };
        let raw = &bytes[pos..pos + len];
        let line = raw.strip_suffix(b"\r").unwrap_or(raw);
        pos += len + 1;
        line_no += 1;
        let err = |msg: String| IoError::at_line(file, line_no, msg);
        let toks: Vec<&[u8]> = tokens(line).collect();
        if line_no == 1 {
            if toks.as_slice() != [b"ply"] {
                return Err(IoError::in_file(
                    file,
                    "not a PLY file (does not start with 'ply')",
                ));
            }
            continue;
        }
        match toks.as_slice() {
            [] => {}
            [b"obj_info", key @ (b"num_cols" | b"num_rows"), value] => {
                let n = parse_i64(value)
                    .and_then(|n| usize::try_from(n).ok())
                    .filter(|&n| n > 0)
                    .ok_or_else(|| err(format!("{} {:?} is invalid", show(key), show(value))))?;
                grid_size[usize::from(*key == b"num_rows")] = Some(n);
            }
            [b"comment", ..] | [b"obj_info", ..] => {}
            [b"format", kind, version] => {
                if *version != b"1.0" {
                    return Err(err(format!("unsupported PLY version {:?}", show(version))));
                }
                encoding = Some(match *kind {
                    b"ascii" => PlyEncoding::Ascii,
                    b"binary_little_endian" => PlyEncoding::BinaryLittleEndian,
                    b"binary_big_endian" => PlyEncoding::BinaryBigEndian,
                    other => return Err(err(format!("unknown PLY format {:?}", show(other)))),
                });
            }
            [b"element", name, count] => {
                let count = parse_i64(count)
                    .and_then(|c| usize::try_from(c).ok())
                    .ok_or_else(|| err(format!("element count {:?} is invalid", show(count))))?;
                elements.push(Element {
                    name: String::from_utf8_lossy(name).into_owned(),
                    count,
                    properties: Vec::new(),
                    line: line_no,
                });
            }
            [b"property", rest @ ..] => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| err("property before any element".to_string()))?;
                let scalar = |name: &[u8]| {
                    Scalar::parse(name)
                        .ok_or_else(|| err(format!("unknown property type {:?}", show(name))))
                };
                let (kind, name) = match rest {
                    [b"list", count, item, name] => {
                        let count = scalar(count)?;
                        if !count.is_integer() {
                            return Err(err("list count type must be an integer type".into()));
                        }
                        (
                            PropertyKind::List {
                                count,
                                item: scalar(item)?,
                            },
                            name,
                        )
                    }
                    [ty, name] => (PropertyKind::Scalar(scalar(ty)?), name),
                    _ => return Err(err(format!("malformed property line {:?}", show(line)))),
                };
                element.properties.push(Property {
                    name: String::from_utf8_lossy(name).into_owned(),
                    kind,
                });
            }
            [b"end_header"] => break,
            _ => return Err(err(format!("unexpected header line {:?}", show(line)))),
        }
    }
    let encoding =
        encoding.ok_or_else(|| IoError::in_file(file, "PLY header has no 'format' line"))?;
    Ok(Header {
        encoding,
        elements,
        body: pos,
        body_line: line_no + 1,
        grid_size,
    })
}

/// A body encoding: yields values one element instance at a time.
trait Source {
    /// Starts the next element instance (ASCII: the next non-empty line).
    fn begin(&mut self) -> Result<(), String>;
    /// Reads one value of type `ty`.
    fn read(&mut self, ty: Scalar) -> Result<Num, String>;
    /// Ends the instance (ASCII: no values may be left on the line).
    fn end(&mut self) -> Result<(), String>;
    /// Where the current instance is, for errors; `kind index` names it.
    fn location(&self, kind: &'static str, index: usize) -> Location;
}

struct AsciiSource<'a, I: Iterator<Item = &'a [u8]>> {
    lines: I,
    line_no: usize,
    tokens: Vec<&'a [u8]>,
    next: usize,
}

impl<'a, I: Iterator<Item = &'a [u8]>> Source for AsciiSource<'a, I> {
    fn begin(&mut self) -> Result<(), String> {
        loop {
            let line = self.lines.next().ok_or("file ends early (truncated?)")?;
            self.line_no += 1;
            self.tokens.clear();
            self.tokens.extend(tokens(line));
            self.next = 0;
            if !self.tokens.is_empty() {
                return Ok(());
            }
        }
    }

    fn read(&mut self, ty: Scalar) -> Result<Num, String> {
        let tok = *self
            .tokens
            .get(self.next)
            .ok_or("line ends early (fewer values than the header declares)")?;
        self.next += 1;
        if ty.is_integer() {
            parse_i64(tok).map(Num::Int)
        } else {
            parse_f64(tok).map(Num::Float)
        }
        .ok_or_else(|| format!("{:?} is not a valid {ty:?} value", show(tok)))
    }

    fn end(&mut self) -> Result<(), String> {
        let extra = self.tokens.len() - self.next;
        if extra > 0 {
            return Err(format!("{extra} more value(s) than the header declares"));
        }
        Ok(())
    }

    fn location(&self, _kind: &'static str, _index: usize) -> Location {
        Location::Line(self.line_no)
    }
}

struct BinarySource<'a> {
    bytes: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Source for BinarySource<'_> {
    fn begin(&mut self) -> Result<(), String> {
        Ok(())
    }

    fn read(&mut self, ty: Scalar) -> Result<Num, String> {
        let size = ty.size();
        let raw = self
            .bytes
            .get(self.pos..self.pos + size)
            .ok_or("file ends early (truncated?)")?;
        self.pos += size;
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(raw);
        if self.big_endian {
            b[..size].reverse();
        }
        // `b` now holds the value in little-endian order.
        Ok(match ty {
            Scalar::I8 => Num::Int(b[0] as i8 as i64),
            Scalar::U8 => Num::Int(b[0] as i64),
            Scalar::I16 => Num::Int(i16::from_le_bytes([b[0], b[1]]) as i64),
            Scalar::U16 => Num::Int(u16::from_le_bytes([b[0], b[1]]) as i64),
            Scalar::I32 => Num::Int(i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64),
            Scalar::U32 => Num::Int(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64),
            Scalar::F32 => Num::Float(f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64),
            Scalar::F64 => Num::Float(f64::from_le_bytes(b)),
        })
    }

    fn end(&mut self) -> Result<(), String> {
        Ok(())
    }

    fn location(&self, kind: &'static str, index: usize) -> Location {
        Location::Element { kind, index }
    }
}

/// What the reader does with an element.
enum Role {
    /// The `vertex` element: property indices of x, y, z.
    Vertex([usize; 3]),
    /// The `face` element: property index of the index list.
    Face(usize),
    /// The `range_grid` element: property index of its list of at most one vertex index.
    Grid(usize),
    /// Anything else: read and drop.
    Skip,
}

fn read_body(
    header: &Header,
    body_len: usize,
    file: &str,
    mut src: impl Source,
) -> Result<PlyBody, IoError> {
    let vertex = header
        .elements
        .iter()
        .find(|e| e.name == "vertex")
        .ok_or_else(|| IoError::in_file(file, "PLY header has no 'vertex' element"))?;
    let n_vertices = vertex.count;
    if n_vertices > u32::MAX as usize {
        return Err(IoError::in_file(file, "more than 2^32 - 1 vertices"));
    }
    let face = header.elements.iter().find(|e| e.name == "face");
    let grid = header.elements.iter().find(|e| e.name == "range_grid");
    let index_list = |element: &Element| {
        element.properties.iter().position(|p| {
            (p.name == "vertex_indices" || p.name == "vertex_index")
                && matches!(p.kind, PropertyKind::List { item, .. } if item.is_integer())
        })
    };
    // Faces win when a file has both; a range grid is read only when there are no faces.
    let mut grid_dims = None;
    let (list_element, list_role) = match (face, grid) {
        (Some(face), _) => {
            let list = index_list(face).ok_or_else(|| {
                IoError::in_file(
                    file,
                    "PLY 'face' element has no integer list 'vertex_indices' or 'vertex_index'",
                )
            })?;
            (face, Role::Face(list))
        }
        (None, Some(grid)) => {
            let list = index_list(grid).ok_or_else(|| {
                IoError::in_file(
                    file,
                    "PLY 'range_grid' element has no integer list 'vertex_indices'",
                )
            })?;
            let [Some(cols), Some(rows)] = header.grid_size else {
                return Err(IoError::in_file(
                    file,
                    "range grid without 'obj_info num_cols' and 'obj_info num_rows'",
                ));
            };
            if cols.checked_mul(rows) != Some(grid.count) {
                return Err(IoError::at_line(
                    file,
                    grid.line,
                    format!(
                        "range_grid has {} cells, but num_cols {cols} x num_rows {rows} = {}",
                        grid.count,
                        cols.saturating_mul(rows)
                    ),
                ));
            }
            grid_dims = Some([cols, rows]);
            (grid, Role::Grid(list))
        }
        // Points alone: an unorganised scan, read with no list element.
        (None, None) => (vertex, Role::Skip),
    };
    let mut xyz = [usize::MAX; 3];
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        xyz[k] = vertex
            .properties
            .iter()
            .position(|p| p.name == *axis && matches!(p.kind, PropertyKind::Scalar(_)))
            .ok_or_else(|| {
                IoError::in_file(file, format!("PLY 'vertex' element has no scalar '{axis}'"))
            })?;
    }

    // Never trust a count for an allocation larger than the file could hold.
    let mut positions = Vec::with_capacity(n_vertices.min(body_len));
    let mut fans = FanBuilder::default();
    let mut cells: Vec<Option<u32>> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    let mut coords = [0.0f64; 3];

    for element in &header.elements {
        let (role, kind) = if std::ptr::eq(element, vertex) {
            (Role::Vertex(xyz), "vertex")
        } else if std::ptr::eq(element, list_element) {
            match list_role {
                Role::Face(q) => (Role::Face(q), "face"),
                Role::Grid(q) => {
                    cells.reserve(element.count.min(body_len));
                    (Role::Grid(q), "cell")
                }
                _ => (Role::Skip, "element"),
            }
        } else {
            (Role::Skip, "element")
        };
        // An element without properties occupies no bytes: walking a huge count of them
        // would only burn time.
        let count = if element.properties.is_empty() {
            0
        } else {
            element.count
        };
        for index in 0..count {
            let fail = |src: &dyn Source, msg: String| {
                let location = src.location(kind, index);
                let message = match location {
                    Location::Line(_) => format!("{} {index}: {msg}", element.name),
                    _ if kind == "element" => format!("({}) {msg}", element.name),
                    _ => msg,
                };
                IoError::malformed(file, location, message)
            };
            src.begin().map_err(|m| fail(&src, m))?;
            for (p, property) in element.properties.iter().enumerate() {
                match property.kind {
                    PropertyKind::Scalar(ty) => {
                        let value = src.read(ty).map_err(|m| fail(&src, m))?;
                        if let Role::Vertex(xyz) = role
                            && let Some(axis) = xyz.iter().position(|&q| q == p)
                        {
                            let v = value.as_f64();
                            if !v.is_finite() {
                                let msg = format!("{} coordinate is {v}", property.name);
                                return Err(fail(&src, msg));
                            }
                            coords[axis] = v;
                        }
                    }
                    PropertyKind::List { count, item } => {
                        let k = src.read(count).map_err(|m| fail(&src, m))?.as_i64();
                        if k < 0 {
                            return Err(fail(&src, format!("negative list length {k}")));
                        }
                        let keep = matches!(role, Role::Face(q) | Role::Grid(q) if q == p);
                        corners.clear();
                        for _ in 0..k {
                            let value = src.read(item).map_err(|m| fail(&src, m))?;
                            if keep {
                                let i = value.as_i64();
                                if i < 0 || i >= n_vertices as i64 {
                                    let what = if kind == "cell" { "vertex" } else { "face" };
                                    let msg = format!(
                                        "{what} index {i} out of range (file has {n_vertices} vertices)"
                                    );
                                    return Err(fail(&src, msg));
                                }
                                corners.push(i as u32);
                            }
                        }
                        match role {
                            // A face of fewer than 3 corners is skipped and counted.
                            Role::Face(q) if q == p => fans.push_face(&corners),
                            Role::Grid(q) if q == p => {
                                if k > 1 {
                                    let msg = format!(
                                        "a range grid cell holds 0 or 1 vertex index, not {k}"
                                    );
                                    return Err(fail(&src, msg));
                                }
                                cells.push(corners.first().copied());
                            }
                            _ => {}
                        }
                    }
                }
            }
            src.end().map_err(|m| fail(&src, m))?;
            if let Role::Vertex(_) = role {
                positions.push(glam::DVec3::from_array(coords));
            }
        }
    }

    match grid_dims {
        Some(dims) => Ok(PlyBody {
            positions,
            faces: None,
            grid: Some((cells, dims)),
        }),
        None if face.is_none() => Ok(PlyBody {
            positions,
            faces: None,
            grid: None,
        }),
        None => {
            if fans.is_empty() {
                return Err(IoError::in_file(
                    file,
                    format!("mesh has no faces{}", skipped_note(fans.skipped())),
                ));
            }
            let faces = fans.finish(&positions);
            Ok(PlyBody {
                positions,
                faces: Some(faces),
                grid: None,
            })
        }
    }
}

/// Writes `soup` as PLY in the given encoding with `double x, y, z` and
/// `list uchar uint vertex_indices`; [`read_ply`] gives back bit-identical f64 values.
pub fn write_ply(
    w: &mut dyn Write,
    soup: &TriangleSoup,
    encoding: PlyEncoding,
) -> std::io::Result<()> {
    crate::soup::ensure_writable(soup)?;
    let format = match encoding {
        PlyEncoding::Ascii => "ascii",
        PlyEncoding::BinaryLittleEndian => "binary_little_endian",
        PlyEncoding::BinaryBigEndian => "binary_big_endian",
    };
    write!(
        w,
        "ply\nformat {format} 1.0\ncomment written by roar-io\nelement vertex {}\n\
         property double x\nproperty double y\nproperty double z\nelement face {}\n\
         property list uchar uint vertex_indices\nend_header\n",
        soup.positions.len(),
        soup.triangles.len()
    )?;
    match encoding {
        PlyEncoding::Ascii => {
            for p in &soup.positions {
                writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
            }
            for t in &soup.triangles {
                writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
            }
        }
        PlyEncoding::BinaryLittleEndian | PlyEncoding::BinaryBigEndian => {
            let big = encoding == PlyEncoding::BinaryBigEndian;
            let f = |v: f64| {
                if big {
                    v.to_be_bytes()
                } else {
                    v.to_le_bytes()
                }
            };
            let u = |v: u32| {
                if big {
                    v.to_be_bytes()
                } else {
                    v.to_le_bytes()
                }
            };
            for p in &soup.positions {
                for v in p.to_array() {
                    w.write_all(&f(v))?;
                }
            }
            for t in &soup.triangles {
                w.write_all(&[3])?;
                for &i in t {
                    w.write_all(&u(i))?;
                }
            }
        }
    }
    Ok(())
}
