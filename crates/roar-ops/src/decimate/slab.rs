//! An open slab of space ([`Slab`]): the side of the cut one thread of
//! [`decimate_in_parallel`](super::decimate_in_parallel) may change.

use glam::DVec3;
use roar_mesh::{HalfedgeId, Mesh};

/// An open slab `lo < p[axis] < hi`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Slab {
    pub(super) axis: usize,
    pub(super) lo: f64,
    pub(super) hi: f64,
}

impl Slab {
    /// Whether `p` lies strictly inside.
    pub(super) fn contains(&self, p: DVec3) -> bool {
        self.lo < p[self.axis] && p[self.axis] < self.hi
    }

    /// Whether collapsing `h` with placement `p` keeps every changed face inside: `p` and every
    /// vertex around both endpoints are inside.
    pub(super) fn holds_collapse(&self, mesh: &Mesh, h: HalfedgeId, p: DVec3) -> bool {
        self.contains(p)
            && [mesh.tail(h), mesh.head(h)].into_iter().all(|v| {
                self.contains(mesh.position(v))
                    && mesh
                        .outgoing(v)
                        .all(|o| self.contains(mesh.position(mesh.head(o))))
            })
    }
}
