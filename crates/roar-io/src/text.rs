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

/// Collects faces as fans of triangles and counts the polygons among them.
#[derive(Debug, Default)]
pub(crate) struct FanBuilder {
    /// The triangles so far.
    pub triangles: Vec<[u32; 3]>,
    /// Faces with more than 3 corners so far.
    pub n_polygons: usize,
}

impl FanBuilder {
    /// Adds a face with `corners.len() >= 3` corners as the fan around its first corner.
    pub fn push_face(&mut self, corners: &[u32]) {
        debug_assert!(corners.len() >= 3, "callers reject faces with < 3 corners");
        if corners.len() > 3 {
            self.n_polygons += 1;
        }
        for k in 1..corners.len().saturating_sub(1) {
            self.triangles
                .push([corners[0], corners[k], corners[k + 1]]);
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
    fn fan_triangulates_polygons_and_counts_them() {
        let mut f = FanBuilder::default();
        f.push_face(&[0, 1, 2]);
        f.push_face(&[3, 4, 5, 6, 7]);
        assert_eq!(f.n_polygons, 1);
        assert_eq!(
            f.triangles,
            vec![[0, 1, 2], [3, 4, 5], [3, 5, 6], [3, 6, 7]]
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
