//! STL, ASCII and binary: reader and writers.
//!
//! STL stores every triangle with its own three corners, so a read soup has `V = 3F` (weld with
//! [`TriangleSoup::welded`] to share them). The encoding is detected from the content, not the
//! name: a file whose size is exactly `84 + 50·n` (with `n` the count at byte 80) is binary, even
//! if it starts with `solid` (many binary exporters write that); otherwise a file starting with
//! `solid` is ASCII. ASCII files may hold several `solid … endsolid` blocks; facet normals are
//! ignored; a loop with more than 3 vertices is triangulated and counted as a polygon, one with
//! fewer than 3 is skipped (with its vertices) and counted.
//!
//! Binary STL stores f32: writing it rounds f64 coordinates to f32, so it cannot round-trip
//! arbitrary f64 (f32-representable coordinates do round-trip). The ASCII writer prints f64
//! with shortest round-trip formatting and does round-trip.

use std::io::Write;

use glam::{DVec3, Vec3};

use crate::error::IoError;
use crate::soup::TriangleSoup;
use crate::text::{FanBuilder, lines, parse_point, show, skipped_note, tokens};

/// Size of the binary header plus the triangle count.
const BINARY_PREAMBLE: usize = 84;
/// Size of one binary triangle record: normal, 3 corners (12 × f32), attribute u16.
const BINARY_RECORD: usize = 50;

/// The two STL encodings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StlEncoding {
    /// Text (`solid … facet normal … endsolid`), f64 coordinates printed to round-trip.
    Ascii,
    /// 80-byte header, u32 count, 50-byte records with f32 coordinates (the compact default).
    #[default]
    Binary,
}

/// Reads an STL file (either encoding, detected from the content); `file` names it in errors.
///
/// Errors: a binary file whose size disagrees with its triangle count (truncated), a file that
/// is neither binary nor starts with `solid`, malformed ASCII statements (with the line),
/// NaN/inf coordinates (line, or triangle index for binary), and no triangles. An ASCII loop of
/// fewer than 3 vertices is skipped and counted in [`TriangleSoup::n_faces_skipped`].
pub fn read_stl(bytes: &[u8], file: &str) -> Result<TriangleSoup, IoError> {
    match detect(bytes) {
        Some(StlEncoding::Binary) => read_binary(bytes, file),
        Some(StlEncoding::Ascii) => read_ascii(bytes, file),
        None if bytes.len() >= BINARY_PREAMBLE => {
            let n = binary_count(bytes);
            Err(IoError::in_file(
                file,
                format!(
                    "not an ASCII STL (no 'solid' at the start) and not a binary STL: \
                     header says {n} triangles ({} bytes) but the file has {} bytes",
                    BINARY_PREAMBLE as u64 + BINARY_RECORD as u64 * n as u64,
                    bytes.len()
                ),
            ))
        }
        None => Err(IoError::in_file(
            file,
            format!(
                "not an STL file ({} bytes: too short for binary, no 'solid' for ASCII)",
                bytes.len()
            ),
        )),
    }
}

/// Which encoding `bytes` is in, if any (see the module docs).
pub fn detect(bytes: &[u8]) -> Option<StlEncoding> {
    if bytes.len() >= BINARY_PREAMBLE {
        let n = binary_count(bytes) as u64;
        if BINARY_PREAMBLE as u64 + BINARY_RECORD as u64 * n == bytes.len() as u64 {
            return Some(StlEncoding::Binary);
        }
    }
    // ASCII STL is text: a NUL byte means a binary file (truncated, or with a wrong count),
    // even if its header starts with "solid".
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace())?;
    let starts_with_solid = bytes[start..]
        .get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"));
    let has_nul = bytes[..bytes.len().min(4096)].contains(&0);
    (starts_with_solid && !has_nul).then_some(StlEncoding::Ascii)
}

fn binary_count(bytes: &[u8]) -> u32 {
    u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]])
}

fn read_binary(bytes: &[u8], file: &str) -> Result<TriangleSoup, IoError> {
    let n = binary_count(bytes) as usize;
    if n == 0 {
        return Err(IoError::in_file(file, "binary STL with 0 triangles"));
    }
    if n.checked_mul(3).is_none_or(|v| v > u32::MAX as usize) {
        return Err(IoError::in_file(file, "more than 2^32 - 1 vertices"));
    }
    let mut positions = Vec::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for (t, record) in bytes[BINARY_PREAMBLE..]
        .chunks_exact(BINARY_RECORD)
        .enumerate()
    {
        for corner in 0..3 {
            let at = 12 + 12 * corner;
            let c = [0, 1, 2].map(|k| {
                let o = at + 4 * k;
                f32::from_le_bytes([record[o], record[o + 1], record[o + 2], record[o + 3]])
            });
            if !c.iter().all(|v| v.is_finite()) {
                return Err(IoError::at_element(
                    file,
                    "triangle",
                    t,
                    format!("corner {corner} has a NaN or infinite coordinate {c:?}"),
                ));
            }
            positions.push(Vec3::from_array(c).as_dvec3());
        }
        let base = 3 * t as u32;
        triangles.push([base, base + 1, base + 2]);
    }
    Ok(TriangleSoup::new(positions, triangles))
}

/// Where the ASCII parser is inside the `solid` grammar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Outside any solid.
    Outside,
    /// Inside `solid`, outside any facet.
    Solid,
    /// Inside `facet`, before `outer loop`.
    Facet,
    /// Inside `outer loop`, collecting vertices.
    Loop,
    /// After `endloop`, before `endfacet`.
    LoopDone,
}

fn read_ascii(bytes: &[u8], file: &str) -> Result<TriangleSoup, IoError> {
    let mut positions: Vec<DVec3> = Vec::new();
    let mut fans = FanBuilder::default();
    let mut corners: Vec<u32> = Vec::new();
    let mut state = State::Outside;
    let mut last_line = 0;
    for (line_no, raw) in lines(bytes) {
        last_line = line_no;
        let mut toks = tokens(raw);
        let Some(keyword) = toks.next() else { continue };
        // Keywords are lower case by the format, but some exporters shout.
        let lower = keyword.to_ascii_lowercase();
        let unexpected = |state: State| {
            IoError::at_line(
                file,
                line_no,
                format!("unexpected {:?} (in state {state:?})", show(keyword)),
            )
        };
        state = match (state, lower.as_slice()) {
            // The solid's name (rest of the line) is free text.
            (State::Outside, b"solid") => State::Solid,
            (State::Solid, b"endsolid") => State::Outside,
            (State::Solid, b"facet") => State::Facet, // the normal is ignored
            (State::Facet, b"outer") => {
                corners.clear();
                State::Loop
            }
            (State::Loop, b"vertex") => {
                let p = parse_point(file, line_no, &mut toks)?;
                if positions.len() >= u32::MAX as usize {
                    return Err(IoError::at_line(
                        file,
                        line_no,
                        "more than 2^32 - 1 vertices",
                    ));
                }
                corners.push(positions.len() as u32);
                positions.push(p);
                State::Loop
            }
            (State::Loop, b"endloop") => {
                // A loop of fewer than 3 vertices is skipped and counted by the builder; its
                // vertices go too, so every vertex still belongs to a facet.
                if corners.len() < 3 {
                    positions.truncate(positions.len() - corners.len());
                }
                fans.push_face(&corners);
                State::LoopDone
            }
            (State::LoopDone, b"endfacet") => State::Solid,
            (state, _) => return Err(unexpected(state)),
        };
    }
    if state != State::Outside {
        return Err(IoError::at_line(
            file,
            last_line,
            "file ends inside a solid (truncated? missing 'endsolid')",
        ));
    }
    if fans.is_empty() {
        return Err(IoError::in_file(
            file,
            format!("ASCII STL without facets{}", skipped_note(fans.skipped())),
        ));
    }
    Ok(fans.finish(&positions).into_soup(positions))
}

/// Writes `soup` as STL in the given encoding (one record per triangle; the normal is the unit
/// normal of the corners, zero for degenerate triangles). Binary rounds coordinates to f32 (see
/// the module docs); ASCII round-trips f64.
pub fn write_stl(
    w: &mut dyn Write,
    soup: &TriangleSoup,
    encoding: StlEncoding,
) -> std::io::Result<()> {
    crate::soup::ensure_writable(soup)?;
    let corner = |i: u32| soup.positions[i as usize];
    let normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(corner);
        (b - a).cross(c - a).normalize_or_zero()
    };
    match encoding {
        StlEncoding::Binary => {
            let mut header = [b' '; 80];
            let text = b"roar-io binary STL";
            header[..text.len()].copy_from_slice(text);
            w.write_all(&header)?;
            let n = u32::try_from(soup.triangles.len()).map_err(|_| {
                std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "binary STL holds at most 2^32 - 1 triangles",
                )
            })?;
            w.write_all(&n.to_le_bytes())?;
            let mut record = [0u8; BINARY_RECORD];
            for t in &soup.triangles {
                let vectors = [normal(t), corner(t[0]), corner(t[1]), corner(t[2])];
                for (k, v) in vectors.iter().enumerate() {
                    for (j, x) in v.as_vec3().to_array().iter().enumerate() {
                        let o = 12 * k + 4 * j;
                        record[o..o + 4].copy_from_slice(&x.to_le_bytes());
                    }
                }
                w.write_all(&record)?;
            }
        }
        StlEncoding::Ascii => {
            writeln!(w, "solid roar")?;
            for t in &soup.triangles {
                let n = normal(t);
                writeln!(w, "facet normal {:?} {:?} {:?}", n.x, n.y, n.z)?;
                writeln!(w, "outer loop")?;
                for &i in t {
                    let p = corner(i);
                    writeln!(w, "vertex {:?} {:?} {:?}", p.x, p.y, p.z)?;
                }
                writeln!(w, "endloop")?;
                writeln!(w, "endfacet")?;
            }
            writeln!(w, "endsolid roar")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO_SOLIDS: &[u8] =
        b"solid a\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n\
   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\nendsolid a\r\nsolid b\r\n\
 facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 1\r\n   vertex 1 0 1\r\n   vertex 1 1 1\r\n\
   vertex 0 1 1\r\n  endloop\r\n endfacet\r\nendsolid b\r\n";

    #[test]
    fn ascii_reads_several_solids_and_fans_polygon_loops() {
        let soup = read_stl(TWO_SOLIDS, "t.stl").unwrap();
        assert_eq!(soup.positions.len(), 7);
        assert_eq!(soup.triangles, vec![[0, 1, 2], [3, 4, 5], [3, 5, 6]]);
        assert_eq!(soup.n_polygons, 1);
    }

    #[test]
    fn upper_case_keywords_are_accepted() {
        let text = String::from_utf8_lossy(TWO_SOLIDS).to_uppercase();
        assert_eq!(
            read_stl(text.as_bytes(), "t.stl").unwrap().triangles.len(),
            3
        );
    }

    #[test]
    fn truncated_binary_starting_with_solid_is_reported_as_binary() {
        let soup = TriangleSoup::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]; 2]);
        let mut bytes = Vec::new();
        write_stl(&mut bytes, &soup, StlEncoding::Binary).unwrap();
        bytes[..5].copy_from_slice(b"solid");
        bytes.pop();
        let e = read_stl(&bytes, "t.stl").unwrap_err().to_string();
        assert!(
            e.contains("header says 2 triangles (184 bytes) but the file has 183"),
            "{e}"
        );
    }

    #[test]
    fn binary_starting_with_solid_is_detected_by_size() {
        let soup = TriangleSoup::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]);
        let mut bytes = Vec::new();
        write_stl(&mut bytes, &soup, StlEncoding::Binary).unwrap();
        bytes[..5].copy_from_slice(b"solid");
        assert_eq!(detect(&bytes), Some(StlEncoding::Binary));
        assert_eq!(read_stl(&bytes, "t.stl").unwrap().positions, soup.positions);
    }

    #[test]
    fn errors_name_file_and_line_or_triangle() {
        let truncated = &TWO_SOLIDS[..TWO_SOLIDS.len() - 30];
        let e = read_stl(truncated, "t.stl").unwrap_err().to_string();
        assert!(e.starts_with("t.stl:"), "{e}");
        let bad = String::from_utf8_lossy(TWO_SOLIDS).replace("vertex 1 0 0", "vertex 1 nan 0");
        let e = read_stl(bad.as_bytes(), "t.stl").unwrap_err().to_string();
        assert!(e.starts_with("t.stl:5: y coordinate"), "{e}");

        let soup = TriangleSoup::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]; 3]);
        let mut bytes = Vec::new();
        write_stl(&mut bytes, &soup, StlEncoding::Binary).unwrap();
        let o = 84 + 2 * 50 + 12 + 4;
        bytes[o..o + 4].copy_from_slice(&f32::INFINITY.to_le_bytes());
        let e = read_stl(&bytes, "t.stl").unwrap_err().to_string();
        assert!(e.starts_with("t.stl: triangle 2: corner 0"), "{e}");
        let e = read_stl(&bytes[..bytes.len() - 1], "t.stl")
            .unwrap_err()
            .to_string();
        assert!(e.contains("header says 3 triangles"), "{e}");
    }
}
