//! Typed `u32` element handles.
//!
//! Why `u32` and not `usize`: half the memory in every connectivity array and better cache use; a
//! mesh would need billions of faces to exhaust it (see lox's `handle.rs`). Handles are plain
//! indices into the mesh's arrays, so a handle is only meaningful for the mesh that produced it
//! and only until the next [`crate::Mesh::compact`].
//!
//! Half-edges are allocated in twin pairs, which makes twins and edges implicit:
//! `twin(h) = h ^ 1`, `edge(h) = h >> 1`, `edge.halfedge() = 2e`.

use std::fmt;

macro_rules! handle {
    ($(#[$doc:meta])* $name:ident, $prefix:literal) => {
        $(#[$doc])*
        #[repr(transparent)]
        #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub struct $name(u32);

        impl $name {
            /// The handle of array slot `index`.
            ///
            /// Debug builds panic if `index` does not fit a `u32` (or is the reserved
            /// `u32::MAX`); release builds truncate.
            #[inline]
            pub fn from_index(index: usize) -> Self {
                debug_assert!(
                    index < u32::MAX as usize,
                    concat!(stringify!($name), "::from_index: index {} does not fit a u32 handle"),
                    index
                );
                Self(index as u32)
            }

            /// The array slot of this handle.
            #[inline]
            pub fn index(self) -> usize {
                self.0 as usize
            }

            /// The raw `u32` value (the array slot).
            #[inline]
            pub fn raw(self) -> u32 {
                self.0
            }
        }

        impl fmt::Debug for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }
    };
}

handle!(
    /// A vertex of a [`crate::Mesh`]; Debug prints `v12`.
    VertexId,
    "v"
);
handle!(
    /// A directed half-edge of a [`crate::Mesh`]; Debug prints `h7`. Its twin is `h ^ 1`.
    HalfedgeId,
    "h"
);
handle!(
    /// An undirected edge (a twin pair of half-edges) of a [`crate::Mesh`]; Debug prints `e3`.
    EdgeId,
    "e"
);
handle!(
    /// A triangle of a [`crate::Mesh`]; Debug prints `f4`.
    FaceId,
    "f"
);

impl HalfedgeId {
    /// The oppositely directed half-edge of the same edge (`h ^ 1`).
    #[inline]
    pub fn twin(self) -> HalfedgeId {
        HalfedgeId(self.0 ^ 1)
    }

    /// The undirected edge this half-edge belongs to (`h >> 1`).
    #[inline]
    pub fn edge(self) -> EdgeId {
        EdgeId(self.0 >> 1)
    }
}

impl EdgeId {
    /// The canonical half-edge of this edge (`2e`); its twin is `2e + 1`.
    #[inline]
    pub fn halfedge(self) -> HalfedgeId {
        HalfedgeId(self.0 << 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn debug_prints_prefix_and_index() {
        assert_eq!(format!("{:?}", VertexId::from_index(12)), "v12");
        assert_eq!(format!("{:?}", HalfedgeId::from_index(7)), "h7");
        assert_eq!(format!("{:?}", EdgeId::from_index(3)), "e3");
        assert_eq!(format!("{:?}", FaceId::from_index(4)), "f4");
    }

    #[test]
    fn twins_and_edges_are_implicit() {
        let h = HalfedgeId::from_index(7);
        assert_eq!(h.twin().index(), 6);
        assert_eq!(h.twin().twin(), h);
        assert_eq!(h.edge().index(), 3);
        assert_eq!(h.edge().halfedge().index(), 6);
        assert_eq!(h.twin().edge(), h.edge());
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "does not fit")]
    fn from_index_is_debug_checked() {
        let _ = VertexId::from_index(u32::MAX as usize);
    }
}
