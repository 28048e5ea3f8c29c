//! OFF (Object File Format): reader and writer.
//!
//! Accepted: a header keyword `OFF` with optional `ST`, `C`, `N` prefixes (`COFF`, `NOFF`,
//! `CNOFF`, `STOFF`, ...), the counts line `V F [E]` (on its own line or after the keyword, even
//! with `V` glued to it as ModelNet40 writes it: `OFF700 620 0`), one vertex per line (first
//! three numbers are the position; colours, normals and texture coordinates after them are
//! ignored), one face per line `k i1 .. ik [colour]` with 0-based indices (polygons are
//! triangulated; faces of fewer than 3 corners are skipped and counted), `#` comments and blank
//! lines anywhere.
//! Not accepted (clear error): binary OFF, `4OFF` and `nOFF` (not 3-D).

use std::io::Write;

use crate::error::IoError;
use crate::soup::TriangleSoup;
use crate::text::{
    FanBuilder, lines, parse_i64, parse_point, show, skipped_note, strip_comment, tokens,
};

/// Reads an OFF file from `bytes`; `file` names it in errors.
///
/// Errors (with the 1-based line): a missing or unknown header, bad counts, malformed or
/// non-finite coordinates, face indices out of range, a file that ends before all declared
/// vertices and faces, and no triangles. Faces with fewer than 3 corners are skipped and counted
/// in [`TriangleSoup::n_faces_skipped`].
pub fn read_off(bytes: &[u8], file: &str) -> Result<TriangleSoup, IoError> {
    // Meaningful lines only: comments stripped, blank lines skipped.
    let mut content = lines(bytes)
        .map(|(n, l)| (n, strip_comment(l)))
        .filter(|(_, l)| tokens(l).next().is_some());

    let (header_line, header) = content
        .next()
        .ok_or_else(|| IoError::in_file(file, "file is empty (expected an OFF header)"))?;
    let mut toks = tokens(header);
    let (keyword, glued) = split_glued_count(toks.next().unwrap_or_default());
    check_keyword(file, header_line, keyword)?;

    // The counts follow the keyword on the same line (the vertex count possibly glued to it),
    // or come on the next line.
    let mut rest: Vec<&[u8]> = glued.into_iter().chain(toks).collect();
    if rest
        .first()
        .is_some_and(|t| t.eq_ignore_ascii_case(b"BINARY"))
    {
        return Err(IoError::at_line(
            file,
            header_line,
            "binary OFF is not supported",
        ));
    }
    let mut counts_line = header_line;
    if rest.is_empty() {
        let (n, l) = content.next().ok_or_else(|| {
            IoError::in_file(
                file,
                "file ends after the header (expected the counts line)",
            )
        })?;
        counts_line = n;
        rest = tokens(l).collect();
    }
    let count = |k: usize, what: &str| -> Result<usize, IoError> {
        let tok = rest
            .get(k)
            .copied()
            .ok_or_else(|| IoError::at_line(file, counts_line, format!("missing {what} count")))?;
        parse_i64(tok)
            .and_then(|v| usize::try_from(v).ok())
            .ok_or_else(|| {
                IoError::at_line(
                    file,
                    counts_line,
                    format!("{what} count {:?} is not a non-negative integer", show(tok)),
                )
            })
    };
    let n_vertices = count(0, "vertex")?;
    let n_faces = count(1, "face")?;
    if n_vertices > u32::MAX as usize {
        return Err(IoError::at_line(
            file,
            counts_line,
            "more than 2^32 - 1 vertices",
        ));
    }

    // Never trust a count for an allocation larger than the file could hold.
    let mut positions = Vec::with_capacity(n_vertices.min(bytes.len() / 6));
    for read in 0..n_vertices {
        let (n, l) = content.next().ok_or_else(|| {
            IoError::in_file(
                file,
                format!("file ends after {read} of {n_vertices} vertices"),
            )
        })?;
        positions.push(parse_point(file, n, &mut tokens(l))?);
    }

    let mut fans = FanBuilder::default();
    let mut corners: Vec<u32> = Vec::new();
    for read in 0..n_faces {
        let (n, l) = content.next().ok_or_else(|| {
            IoError::in_file(file, format!("file ends after {read} of {n_faces} faces"))
        })?;
        let mut toks = tokens(l);
        let first = toks.next().unwrap_or_default();
        let k = parse_i64(first).ok_or_else(|| {
            IoError::at_line(
                file,
                n,
                format!("face corner count {:?} is not an integer", show(first)),
            )
        })?;
        if k < 0 {
            return Err(IoError::at_line(
                file,
                n,
                format!("face corner count {k} is negative"),
            ));
        }
        corners.clear();
        for c in 0..k {
            let tok = toks.next().ok_or_else(|| {
                IoError::at_line(
                    file,
                    n,
                    format!("face declares {k} corners but has only {c}"),
                )
            })?;
            let i = parse_i64(tok).ok_or_else(|| {
                IoError::at_line(
                    file,
                    n,
                    format!("face index {:?} is not an integer", show(tok)),
                )
            })?;
            if i < 0 || i >= n_vertices as i64 {
                return Err(IoError::at_line(
                    file,
                    n,
                    format!("face index {i} out of range (file has {n_vertices} vertices)"),
                ));
            }
            corners.push(i as u32);
        }
        // A face of fewer than 3 corners is skipped and counted by the builder.
        fans.push_face(&corners);
    }

    if fans.is_empty() {
        return Err(IoError::in_file(
            file,
            format!("mesh has no faces{}", skipped_note(fans.skipped())),
        ));
    }
    Ok(fans.finish(&positions).into_soup(positions))
}

/// Splits a vertex count glued to the keyword (`OFF700` as ModelNet40 writes it, also `COFF12`)
/// into the keyword and the count, as mainstream loaders read it; any other token is returned
/// whole, for [`check_keyword`] to judge.
fn split_glued_count(token: &[u8]) -> (&[u8], Option<&[u8]>) {
    let Some(at) = token.windows(3).position(|w| w == b"OFF") else {
        return (token, None);
    };
    let (keyword, count) = token.split_at(at + 3);
    if !count.is_empty() && count.iter().all(u8::is_ascii_digit) {
        (keyword, Some(count))
    } else {
        (token, None)
    }
}

/// Accepts `OFF` with optional `ST`, `C`, `N` prefixes in that order.
fn check_keyword(file: &str, line: usize, keyword: &[u8]) -> Result<(), IoError> {
    let bad = || {
        IoError::at_line(
            file,
            line,
            format!(
                "not an OFF file: header is {:?}, expected OFF",
                show(keyword)
            ),
        )
    };
    let prefix = keyword.strip_suffix(b"OFF").ok_or_else(bad)?;
    let prefix = prefix.strip_prefix(b"ST").unwrap_or(prefix);
    let prefix = prefix.strip_prefix(b"C").unwrap_or(prefix);
    let prefix = prefix.strip_prefix(b"N").unwrap_or(prefix);
    if prefix.is_empty() {
        Ok(())
    } else if prefix.contains(&b'4') || prefix.contains(&b'n') {
        Err(IoError::at_line(
            file,
            line,
            format!("{:?}: only 3-D OFF is supported", show(keyword)),
        ))
    } else {
        Err(bad())
    }
}

/// Writes `soup` as OFF; coordinates use Rust's shortest round-trip formatting, so
/// [`read_off`] gives back bit-identical f64 values.
pub fn write_off(w: &mut dyn Write, soup: &TriangleSoup) -> std::io::Result<()> {
    crate::soup::ensure_writable(soup)?;
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", soup.positions.len(), soup.triangles.len())?;
    for p in &soup.positions {
        writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    for t in &soup.triangles {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_variants_comments_colours_and_polygons() {
        let text = b"COFF\r\n# a comment\r\n\r\n4 2 0\r\n0 0 0 255 0 0 255\r\n1 0 0 1 1 1 1\r\n\
1 1 0 0 0 0 0\r\n0 1 0 0 0 0 0\r\n4  0 1 2 3 255 0 0\r\n3 0 2 3\r\n";
        let soup = read_off(text, "t.off").unwrap();
        assert_eq!(soup.positions.len(), 4);
        assert_eq!(soup.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert_eq!(soup.n_polygons, 1);
        let inline = read_off(b"OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "t.off").unwrap();
        assert_eq!(inline.triangles.len(), 1);
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases: [(&[u8], &str); 11] = [
            (b"PLY\n3 1 0\n", "t.off:1: not an OFF file"),
            (b"4OFF\n3 1 0\n", "t.off:1: \"4OFF\": only 3-D"),
            (
                b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
                "t.off:6: face index 3 out of range",
            ),
            (
                b"OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n",
                "t.off:4: y coordinate",
            ),
            (
                b"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                "t.off: file ends after 1 of 2 faces",
            ),
            (
                b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
                "t.off: mesh has no faces; 1 face(s) with fewer than 3 corners skipped",
            ),
            (b"OFF\n0 0 0\n", "t.off: mesh has no faces"),
            (
                b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n-1 0\n",
                "t.off:6: face corner count -1 is negative",
            ),
            (
                b"OFFx3 1 0\n",
                "t.off:1: not an OFF file: header is \"OFFx3\"",
            ),
            (b"4OFF3 1 0\n", "t.off:1: \"4OFF\": only 3-D"),
            (b"OFF3\n1 0\n", "t.off:1: missing face count"),
        ];
        for (text, want) in cases {
            let e = read_off(text, "t.off").unwrap_err().to_string();
            assert!(e.starts_with(want), "{e:?} should start with {want:?}");
        }
    }
}
