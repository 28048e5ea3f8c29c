//! The one error type of this crate.
//!
//! Every message is a single line that starts with the file it is about, then (where it applies)
//! the line number (`bunny.obj:1234: ...`) or the element (`box.stl: triangle 17: ...`), then what
//! is wrong. That is what a user needs to find the problem in the file.

use std::fmt;
use std::path::PathBuf;

use thiserror::Error;

/// Where in a file a problem was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// The file as a whole (for example "no triangles").
    File,
    /// A 1-based line of a text file.
    Line(usize),
    /// A 0-based element of a binary file or of a validated soup, e.g. `vertex 12`, `face 7`.
    Element {
        /// What kind of element (`"vertex"`, `"face"`, `"triangle"`, ...).
        kind: &'static str,
        /// Its 0-based index in the file.
        index: usize,
    },
}

impl fmt::Display for Location {
    /// Formats as the part between the file name and the message: `""`, `":12"` or `": face 7"`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::File => Ok(()),
            Location::Line(line) => write!(f, ":{line}"),
            Location::Element { kind, index } => write!(f, ": {kind} {index}"),
        }
    }
}

/// Errors of reading and writing meshes and images.
#[derive(Debug, Error)]
pub enum IoError {
    /// The operating system failed to read, create, write or rename a file.
    #[error("{}: {source}", path.display())]
    Os {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file's content is not a valid mesh of its format (truncated, malformed numbers,
    /// NaN/inf coordinates, indices out of range, no triangles, ...).
    #[error("{file}{location}: {message}")]
    Malformed {
        /// The file's name as given to the reader.
        file: String,
        /// Where in the file.
        location: Location,
        /// What is wrong, in one line.
        message: String,
    },
    /// The file name's extension names no mesh format we know.
    #[error(
        "{}: unknown mesh file extension {extension:?} (expected one of: obj, ply, stl, off, gltf, glb)",
        path.display()
    )]
    UnknownFormat {
        /// The file concerned.
        path: PathBuf,
        /// The extension found (empty when there is none).
        extension: String,
    },
    /// The data handed to a writer cannot be written (invalid soup, wrong image buffer size,
    /// an encoder failure).
    #[error("{}: {message}", path.display())]
    InvalidInput {
        /// The file that was to be written.
        path: PathBuf,
        /// What is wrong, in one line.
        message: String,
    },
}

impl IoError {
    /// A [`IoError::Malformed`] error at `location` of `file`.
    pub fn malformed(file: &str, location: Location, message: impl Into<String>) -> Self {
        IoError::Malformed {
            file: file.to_string(),
            location,
            message: message.into(),
        }
    }

    /// A [`IoError::Malformed`] error at 1-based `line` of `file`.
    pub fn at_line(file: &str, line: usize, message: impl Into<String>) -> Self {
        Self::malformed(file, Location::Line(line), message)
    }

    /// A [`IoError::Malformed`] error at element `kind index` of `file`.
    pub fn at_element(
        file: &str,
        kind: &'static str,
        index: usize,
        message: impl Into<String>,
    ) -> Self {
        Self::malformed(file, Location::Element { kind, index }, message)
    }

    /// A [`IoError::Malformed`] error about `file` as a whole.
    pub fn in_file(file: &str, message: impl Into<String>) -> Self {
        Self::malformed(file, Location::File, message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_one_line_with_file_and_location() {
        let e = IoError::at_line(
            "bunny.obj",
            1234,
            "face index 9999 out of range (file has 35947 vertices)",
        );
        assert_eq!(
            e.to_string(),
            "bunny.obj:1234: face index 9999 out of range (file has 35947 vertices)"
        );
        let e = IoError::at_element("box.stl", "triangle", 17, "coordinate is NaN");
        assert_eq!(e.to_string(), "box.stl: triangle 17: coordinate is NaN");
        let e = IoError::in_file("x.off", "no triangles");
        assert_eq!(e.to_string(), "x.off: no triangles");
    }
}
