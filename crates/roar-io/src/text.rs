//! Small helpers shared by the readers: lines and tokens of text files, number parsing,
//! fan triangulation.

use glam::DVec3;

use crate::error::IoError;

/// The lines of a byte buffer with their 1-based numbers; `\n`, `\r\n` and a lone trailing `\r`
/// all end a line, and the line terminator is not part of the line.
pub(crate) fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let body = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    // `split` yields one empty piece for an empty buffer; an empty file has no lines.
    let count = if bytes.is_empty() { 0 } else { usize::MAX };
    body.split(|&b| b == b'\n')
        .take(count)
        .enumerate()
        .map(|(i, line)| (i + 1, line.strip_suffix(b"\r").unwrap_or(line)))
}

/// The part of `line` before the first `#` (comments in OBJ and OFF).
pub(crate) fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// The whitespace-separated tokens of a line.
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}

/// A token shown in an error message (lossy UTF-8, cut to a readable length).
pub(crate) fn show(token: &[u8]) -> String {
    let s = String::from_utf8_lossy(token);
    if s.chars().count() > 40 {
        format!("{}...", s.chars().take(40).collect::<String>())
    } else {
        s.into_owned()
    }
}

/// Parses a decimal floating-point number (any form Rust's `f64::from_str` accepts).
pub(crate) fn parse_f64(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// Parses a signed decimal integer.
pub(crate) fn parse_i64(token: &[u8]) -> Option<i64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// Parses three finite coordinates from the next tokens, or says at `line` what is wrong.
pub(crate) fn parse_point<'a>(
    file: &str,
    line: usize,
    toks: &mut impl Iterator<Item = &'a [u8]>,
) -> Result<DVec3, IoError> {
    let mut c = [0.0; 3];
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let tok = toks
            .next()
            .ok_or_else(|| IoError::at_line(file, line, format!("missing {axis} coordinate")))?;
        let value = parse_f64(tok).ok_or_else(|| {
            IoError::at_line(
                file,
                line,
                format!("{axis} coordinate {:?} is not a number", show(tok)),
            )
        })?;
        if !value.is_finite() {
            return Err(IoError::at_line(
                file,
                line,
                format!("{axis} coordinate {:?} is not finite", show(tok)),
            ));
        }
        c[k] = value;
    }
    Ok(DVec3::from_array(c))
}

/// `"; N face(s) with fewer than 3 corners skipped"` when faces were skipped, else `""`: for the
/// "no faces" errors, so a file of nothing but such faces says why it has none.
pub(crate) fn skipped_note(skipped: usize) -> String {
    if skipped == 0 {
        String::new()
    } else {
        format!("; {skipped} face(s) with fewer than 3 corners skipped")
    }
}

/// Collects faces and turns them into triangles: triangles as they come, polygons (more than 3
/// corners) by ear clipping in their own plane once the positions are known
/// ([`FanBuilder::finish`]; vertices may follow faces in a PLY file).
#[derive(Debug, Default)]
pub(crate) struct FanBuilder {
    /// The triangles so far (polygons not yet included).
    triangles: Vec<[u32; 3]>,
    /// Each polygon with the length `triangles` had when it came, to keep the file's order.
    polygons: Vec<(usize, Vec<u32>)>,
    /// Faces with fewer than 3 corners, skipped.
    skipped: usize,
}

/// The triangles of every face, in file order, and the polygon counts.
pub(crate) struct Faces {
    /// The triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Faces with more than 3 corners.
    pub n_polygons: usize,
    /// Polygons that could not be triangulated cleanly (see
    /// [`crate::polygon::triangulate_polygon`]).
    pub n_polygons_unclean: usize,
    /// Faces with fewer than 3 corners, skipped.
    pub n_faces_skipped: usize,
}

impl Faces {
    /// The soup of these faces over `positions`.
    pub fn into_soup(self, positions: Vec<DVec3>) -> crate::soup::TriangleSoup {
        crate::soup::TriangleSoup {
            positions,
            triangles: self.triangles,
            n_polygons: self.n_polygons,
            n_polygons_unclean: self.n_polygons_unclean,
            n_faces_skipped: self.n_faces_skipped,
        }
    }
}

impl FanBuilder {
    /// Adds a face. One with fewer than 3 corners (a point or a line segment) bounds no surface:
    /// it is skipped and counted, since real files have them and they are no reason to refuse
    /// the rest.
    pub fn push_face(&mut self, corners: &[u32]) {
        if corners.len() < 3 {
            self.skipped += 1;
        } else if corners.len() > 3 {
            self.polygons.push((self.triangles.len(), corners.to_vec()));
        } else {
            self.triangles.push([corners[0], corners[1], corners[2]]);
        }
    }

    /// How many faces were skipped so far for having fewer than 3 corners.
    pub fn skipped(&self) -> usize {
        self.skipped
    }

    /// Whether no face with at least 3 corners was added.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty() && self.polygons.is_empty()
    }

    /// Triangulates the polygons against `positions` and returns every face's triangles.
    pub fn finish(self, positions: &[DVec3]) -> Faces {
        let n_polygons = self.polygons.len();
        if n_polygons == 0 {
            return Faces {
                triangles: self.triangles,
                n_polygons,
                n_polygons_unclean: 0,
                n_faces_skipped: self.skipped,
            };
        }
        let mut triangles = Vec::with_capacity(self.triangles.len() + 2 * n_polygons);
        let mut n_polygons_unclean = 0;
        let mut copied = 0;
        for (at, corners) in &self.polygons {
            triangles.extend_from_slice(&self.triangles[copied..*at]);
            copied = *at;
            if !crate::polygon::triangulate_polygon(positions, corners, &mut triangles) {
                n_polygons_unclean += 1;
            }
        }
        triangles.extend_from_slice(&self.triangles[copied..]);
        Faces {
            triangles,
            n_polygons,
            n_polygons_unclean,
            n_faces_skipped: self.skipped,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_handle_crlf_and_missing_final_newline() {
        let got: Vec<_> = lines(b"a\r\nb\n\nc").collect();
        assert_eq!(
            got,
            vec![
                (1, &b"a"[..]),
                (2, &b"b"[..]),
                (3, &b""[..]),
                (4, &b"c"[..])
            ]
        );
        let got: Vec<_> = lines(b"a\n").collect();
        assert_eq!(got, vec![(1, &b"a"[..])]);
        assert_eq!(lines(b"").count(), 0);
    }

    #[test]
    fn polygons_are_triangulated_in_file_order_and_counted() {
        // A convex pentagon (a fan), a triangle, a concave quad (an arrowhead with its notch at
        // corner 10, listed from corner 9).
        let mut positions: Vec<DVec3> = (0..8)
            .map(|k| {
                let t = k as f64 / 5.0 * std::f64::consts::TAU;
                DVec3::new(t.cos(), t.sin(), 0.0)
            })
            .collect();
        positions.extend([
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(2.0, -1.0, 0.0),
        ]);
        let mut f = FanBuilder::default();
        f.push_face(&[0, 1, 2]);
        f.push_face(&[3, 4, 5, 6, 7]);
        f.push_face(&[0, 2, 1]);
        f.push_face(&[9, 10, 11, 8]);
        let faces = f.finish(&positions);
        assert_eq!(faces.n_polygons, 2);
        assert_eq!(faces.n_polygons_unclean, 0);
        assert_eq!(
            faces.triangles,
            vec![
                [0, 1, 2],
                [3, 4, 5],
                [3, 5, 6],
                [3, 6, 7],
                [0, 2, 1],
                // The fan's (9, 10, 11) would cover the notch, outside the polygon.
                [10, 11, 8],
                [9, 10, 8],
            ]
        );
    }

    #[test]
    fn parse_point_rejects_nan_inf_and_garbage() {
        for bad in ["1 2 nan", "inf 0 0", "1 2", "1 x 3"] {
            let mut t = tokens(bad.as_bytes());
            assert!(parse_point("f", 3, &mut t).is_err(), "{bad}");
        }
        let mut t = tokens(b"1 -2.5e1 .5");
        assert_eq!(
            parse_point("f", 1, &mut t).unwrap(),
            DVec3::new(1.0, -25.0, 0.5)
        );
    }
}
