//! The scanners' lines of sight: a point that every scanner sees only through surface it
//! measured is inside the object, whatever the winding number says there.
//!
//! A range scan is a height field seen from its scanner: each measured point lies on the first
//! surface along a line of sight, and the space between it and the scanner is empty. Inside the
//! object, the line of sight from a point toward any scanner leaves through the object's surface
//! on that scanner's side, which the scanner measured; outside, some scanner looks at the point
//! past the object (space carving, Kutulakos and Seitz 2000, in its simplest form). A set of
//! scans that leaves wide regions unseen (four bunny scans without its sides) gives the winding
//! number too little solid angle there, and tunnels open between the unseen regions; the lines
//! of sight close them. A hole in a patch (a grazing triangle dropped, no return) lets its
//! scanner look through, so points behind it are not claimed: the rule only ever adds solid
//! where every scanner is blocked.

use glam::DVec3;

/// One scanner's view of the object: the surface it measured and the direction toward it.
#[derive(Clone, Debug, PartialEq)]
pub struct ScannerView {
    /// Unit direction from the object toward the scanner, the same for every point (the scan
    /// frame's +z, placed: range scanners look along parallel lines).
    pub toward_scanner: DVec3,
    /// The measured surface (the scan's patch), in the coordinates of the soup being initialised.
    pub positions: Vec<DVec3>,
    /// Its triangles, indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// Largest number of cells of one depth map; coarser cells beyond it.
const MAX_CELLS: usize = 1 << 24;

/// A view's nearest measured surface per cell of the plane facing its scanner: for each cell,
/// the largest height (toward the scanner) of the patch triangles whose box overlaps it. Taking
/// the box and the triangle's highest corner errs toward occlusion by at most a cell and a
/// triangle's height, which only touches voxels next to the surface.
pub(crate) struct DepthMap {
    u: DVec3,
    v: DVec3,
    w: DVec3,
    min: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    nearest: Vec<f64>,
}

impl DepthMap {
    /// The depth map of `view` with square cells of side `cell` (at least; coarser when the
    /// patch would need more than [`MAX_CELLS`]); `None` when the view has no triangle or no
    /// usable direction.
    pub(crate) fn new(view: &ScannerView, cell: f64) -> Option<DepthMap> {
        let w = view.toward_scanner.try_normalize()?;
        let u = w.any_orthonormal_vector();
        let v = w.cross(u);
        let corners = |t: &[u32; 3]| t.map(|i| view.positions[i as usize]);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for t in &view.triangles {
            for p in corners(t) {
                let q = [p.dot(u), p.dot(v)];
                for k in 0..2 {
                    lo[k] = lo[k].min(q[k]);
                    hi[k] = hi[k].max(q[k]);
                }
            }
        }
        if !(lo[0].is_finite() && hi[0].is_finite() && cell > 0.0) {
            return None;
        }
        let mut cell = cell;
        let dims = loop {
            let dims = [0, 1].map(|k| ((hi[k] - lo[k]) / cell) as usize + 1);
            if dims[0] * dims[1] <= MAX_CELLS {
                break dims;
            }
            cell *= 2.0;
        };
        let mut map = DepthMap {
            u,
            v,
            w,
            min: lo,
            cell,
            dims,
            nearest: vec![f64::NEG_INFINITY; dims[0] * dims[1]],
        };
        for t in &view.triangles {
            let c = corners(t);
            let height = c.iter().map(|p| p.dot(w)).fold(f64::NEG_INFINITY, f64::max);
            let (mut a, mut b) = ([usize::MAX; 2], [0usize; 2]);
            for p in c {
                let cell = map.cell_of(p);
                for k in 0..2 {
                    a[k] = a[k].min(cell[k]);
                    b[k] = b[k].max(cell[k]);
                }
            }
            for j in a[1]..=b[1] {
                for i in a[0]..=b[0] {
                    let slot = &mut map.nearest[j * dims[0] + i];
                    *slot = slot.max(height);
                }
            }
        }
        Some(map)
    }

    /// The cell of `p`'s projection, clamped to the map.
    fn cell_of(&self, p: DVec3) -> [usize; 2] {
        let q = [p.dot(self.u), p.dot(self.v)];
        [0, 1].map(|k| {
            let x = ((q[k] - self.min[k]) / self.cell).floor().max(0.0) as usize;
            x.min(self.dims[k] - 1)
        })
    }

    /// Whether measured surface lies between `p` and the scanner.
    pub(crate) fn occludes(&self, p: DVec3) -> bool {
        let q = [p.dot(self.u), p.dot(self.v)];
        let outside = (0..2)
            .any(|k| q[k] < self.min[k] || q[k] >= self.min[k] + self.cell * self.dims[k] as f64);
        if outside {
            return false;
        }
        let [i, j] = self.cell_of(p);
        self.nearest[j * self.dims[0] + i] > p.dot(self.w)
    }
}

/// Whether every map occludes `p` (false when there is none).
pub(crate) fn hidden_from_every_scanner(maps: &[DepthMap], p: DVec3) -> bool {
    !maps.is_empty() && maps.iter().all(|m| m.occludes(p))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square patch of side 2 at height `z`, centred at the origin, seen from +z.
    fn square(z: f64) -> ScannerView {
        ScannerView {
            toward_scanner: DVec3::Z,
            positions: vec![
                DVec3::new(-1.0, -1.0, z),
                DVec3::new(1.0, -1.0, z),
                DVec3::new(1.0, 1.0, z),
                DVec3::new(-1.0, 1.0, z),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    #[test]
    fn points_behind_the_patch_are_occluded_and_others_are_not() {
        let map = DepthMap::new(&square(0.5), 0.1).unwrap();
        assert!(map.occludes(DVec3::new(0.2, -0.3, 0.0)));
        assert!(
            !map.occludes(DVec3::new(0.2, -0.3, 0.7)),
            "in front of the patch"
        );
        assert!(!map.occludes(DVec3::new(1.5, 0.0, 0.0)), "beside the patch");
        // Seen from the other side, the same patch hides the points above it.
        let mut below = square(0.5);
        below.toward_scanner = -DVec3::Z;
        let map = DepthMap::new(&below, 0.1).unwrap();
        assert!(map.occludes(DVec3::new(0.2, -0.3, 0.7)));
        assert!(!map.occludes(DVec3::new(0.2, -0.3, 0.0)));
    }

    #[test]
    fn a_point_must_be_hidden_from_every_scanner() {
        // Two scanners above and below a slab: its inside is hidden from both.
        let top = DepthMap::new(&square(0.5), 0.1).unwrap();
        let mut bottom = square(-0.5);
        bottom.toward_scanner = -DVec3::Z;
        let bottom = DepthMap::new(&bottom, 0.1).unwrap();
        let maps = [top, bottom];
        assert!(hidden_from_every_scanner(&maps, DVec3::ZERO));
        assert!(!hidden_from_every_scanner(&maps, DVec3::new(0.0, 0.0, 0.8)));
        assert!(!hidden_from_every_scanner(
            &maps[..1],
            DVec3::new(0.0, 0.0, 0.8)
        ));
        assert!(!hidden_from_every_scanner(&[], DVec3::ZERO));
        // A scanner with nothing measured gives no map.
        let empty = ScannerView {
            toward_scanner: DVec3::X,
            positions: Vec::new(),
            triangles: Vec::new(),
        };
        assert!(DepthMap::new(&empty, 0.1).is_none());
    }
}
