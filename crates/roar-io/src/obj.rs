//! Wavefront OBJ: our own small reader (positions and faces only) and writer.
//!
//! Reading keeps the file's global vertex numbering across `o`/`g` groups (tools that count
//! topology "by index" see exactly the file's vertices), resolves negative (relative) indices,
//! takes the position part of `f a/b/c` corners, triangulates polygons, skips (and counts) faces
//! of fewer than 3 corners, and ignores everything else (`vt vn vp l p o g s mtllib usemtl`,
//! comments, vertex colours and `w` after `v x y z`). Material libraries are never opened, so a
//! missing `.mtl` does not matter.

use std::io::Write;

use crate::error::IoError;
use crate::soup::TriangleSoup;
use crate::text::{
    FanBuilder, lines, parse_i64, parse_point, show, skipped_note, strip_comment, tokens,
};

/// Reads an OBJ file's positions and faces from `bytes`; `file` names it in errors.
///
/// Errors (with the 1-based line): malformed or non-finite coordinates, index 0, an index outside
/// the file's vertices; and no triangles at all. Faces with fewer than 3 corners are skipped and
/// counted in [`TriangleSoup::n_faces_skipped`].
pub fn read_obj(bytes: &[u8], file: &str) -> Result<TriangleSoup, IoError> {
    let mut positions = Vec::new();
    let mut fans = FanBuilder::default();
    let mut corners: Vec<u32> = Vec::new();
    // The largest 1-based index that pointed past the vertices read so far (OBJ allows faces
    // before their vertices), with its line: checked once all vertices are known.
    let mut forward: Option<(usize, i64)> = None;

    for (line_no, raw) in lines(bytes) {
        let mut toks = tokens(strip_comment(raw));
        let Some(keyword) = toks.next() else { continue };
        match keyword {
            b"v" => positions.push(parse_point(file, line_no, &mut toks)?),
            b"f" => {
                corners.clear();
                let n = positions.len() as i64;
                for tok in toks {
                    // `a`, `a/b`, `a//c`, `a/b/c`: the position index comes first.
                    let index_part = tok.split(|&b| b == b'/').next().unwrap_or(tok);
                    let i = parse_i64(index_part).ok_or_else(|| {
                        IoError::at_line(
                            file,
                            line_no,
                            format!("face corner {:?} is not a vertex index", show(tok)),
                        )
                    })?;
                    let zero_based = match i {
                        0 => {
                            return Err(IoError::at_line(
                                file,
                                line_no,
                                "face index 0 is invalid (OBJ indices start at 1)",
                            ));
                        }
                        i if i > 0 => i - 1,
                        i => n + i,
                    };
                    if zero_based < 0 {
                        return Err(IoError::at_line(
                            file,
                            line_no,
                            format!(
                                "relative face index {i} points before the first vertex \
                                 ({n} vertices so far)"
                            ),
                        ));
                    }
                    if zero_based > u32::MAX as i64 - 1 {
                        return Err(IoError::at_line(
                            file,
                            line_no,
                            format!("face index {i} is too large"),
                        ));
                    }
                    if zero_based >= n && forward.is_none_or(|(_, f)| i > f) {
                        forward = Some((line_no, i));
                    }
                    corners.push(zero_based as u32);
                }
                // A face of fewer than 3 corners is skipped and counted by the builder.
                fans.push_face(&corners);
            }
            // vt vn vp l p o g s mtllib usemtl and other statements carry nothing we keep.
            _ => {}
        }
    }

    if let Some((line_no, i)) = forward
        && i > positions.len() as i64
    {
        return Err(IoError::at_line(
            file,
            line_no,
            format!(
                "face index {i} out of range (file has {} vertices)",
                positions.len()
            ),
        ));
    }
    if positions.len() > u32::MAX as usize {
        return Err(IoError::in_file(file, "more than 2^32 - 1 vertices"));
    }
    if fans.is_empty() {
        return Err(IoError::in_file(
            file,
            format!(
                "no faces found ({} vertices{}); empty or not an OBJ mesh",
                positions.len(),
                skipped_note(fans.skipped())
            ),
        ));
    }
    Ok(fans.finish(&positions).into_soup(positions))
}

/// Writes `soup` as OBJ (`v` lines, then `f` lines with 1-based indices). Coordinates use Rust's
/// shortest round-trip formatting, so [`read_obj`] gives back bit-identical f64 values.
pub fn write_obj(w: &mut dyn Write, soup: &TriangleSoup) -> std::io::Result<()> {
    crate::soup::ensure_writable(soup)?;
    writeln!(
        w,
        "# roar-io: {} vertices, {} triangles",
        soup.positions.len(),
        soup.triangles.len()
    )?;
    for p in &soup.positions {
        writeln!(w, "v {:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    for t in &soup.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn reads_groups_slashes_negative_indices_and_polygons() {
        let text =
            b"# comment\r\nmtllib missing.mtl\r\no a\r\nv 0 0 0\r\nv 1 0 0 1.0 0.5 0.5 0.5\r\n\
v 1 1 0\r\nv 0 1 0\r\nvt 0 0\r\nvn 0 0 1\r\ng b\r\nusemtl red\r\ns off\r\n\
f 1/1/1 2/1/1 3/1/1 4/1/1\r\nf -4//1 -2//1 -1//1\r\nl 1 2\r\n";
        let soup = read_obj(text, "t.obj").unwrap();
        assert_eq!(soup.positions.len(), 4);
        assert_eq!(soup.positions[1], DVec3::X);
        assert_eq!(soup.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert_eq!(soup.n_polygons, 1);
    }

    #[test]
    fn faces_may_come_before_their_vertices() {
        let soup = read_obj(b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "t.obj").unwrap();
        assert_eq!(soup.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases: [(&[u8], &str); 7] = [
            (
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
                "t.obj:4: face index 9 out of range",
            ),
            (
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
                "t.obj:4: face index 0",
            ),
            (
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
                "t.obj:4: relative face index -4",
            ),
            (
                b"v 0 0 0\nv 1 0 nan\n",
                "t.obj:2: z coordinate \"nan\" is not finite",
            ),
            (b"v 0 0 0\nv 1 0\n", "t.obj:2: missing z"),
            (
                b"v 0 0 0\nv 1 0 0\nf 1 2\n",
                "t.obj: no faces found (2 vertices; 1 face(s) with fewer than 3 corners skipped)",
            ),
            (b"v 0 0 0\n", "t.obj: no faces found"),
        ];
        for (text, want) in cases {
            let e = read_obj(text, "t.obj").unwrap_err().to_string();
            assert!(e.starts_with(want), "{e:?} should start with {want:?}");
        }
    }

    #[test]
    fn write_then_read_is_bit_identical() {
        let soup = TriangleSoup::new(
            vec![
                DVec3::new(0.1, -1e-300, 1e300),
                DVec3::new(std::f64::consts::PI, -0.0, 123_456_789.123_456_78),
                DVec3::new(f64::MIN_POSITIVE, f64::MAX, -f64::EPSILON),
            ],
            vec![[0, 1, 2], [2, 1, 0]],
        );
        let mut bytes = Vec::new();
        write_obj(&mut bytes, &soup).unwrap();
        let back = read_obj(&bytes, "t.obj").unwrap();
        assert_eq!(back.triangles, soup.triangles);
        for (a, b) in back.positions.iter().zip(&soup.positions) {
            assert_eq!(
                a.to_array().map(f64::to_bits),
                b.to_array().map(f64::to_bits)
            );
        }
    }
}
