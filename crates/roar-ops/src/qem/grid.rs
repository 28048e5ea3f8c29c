//! A dynamic uniform grid over face boxes: the broad phase of the self-intersection veto while
//! the mesh changes under it (a [`roar_mesh::spatial::TriangleBvh`] cannot follow faces whose
//! vertex indices change, and rebuilding it after every collapse costs O(F log F)).
//!
//! Each face is listed in every cell its box overlaps; faces spanning more than
//! [`MAX_CELLS_PER_FACE`] cells go to an always-scanned `oversized` list. Insert and remove are
//! O(cells of the face); the caller rebuilds with a coarser cell when faces have grown.

use roar_mesh::spatial::Aabb;

/// Faces overlapping more cells than this are kept in a flat list instead.
const MAX_CELLS_PER_FACE: i64 = 64;

type Cell = [i32; 3];

#[derive(Debug, Clone, Copy)]
enum Slot {
    Absent,
    Cells { lo: Cell, hi: Cell },
    Oversized,
}

/// A face listed in a bucket, with its box rounded outward to `f32` so that a query can reject
/// most entries while scanning the bucket sequentially.
#[derive(Debug, Clone, Copy)]
struct Entry {
    face: u32,
    lo: [f32; 3],
    hi: [f32; 3],
}

/// Largest `f32` not above `x`.
fn f32_down(x: f64) -> f32 {
    let m = x as f32;
    if m as f64 > x { m.next_down() } else { m }
}

/// Smallest `f32` not below `x`.
fn f32_up(x: f64) -> f32 {
    let m = x as f32;
    if (m as f64) < x { m.next_up() } else { m }
}

/// `b` rounded outward to `f32`.
fn f32_box(b: &Aabb) -> ([f32; 3], [f32; 3]) {
    (
        [b.min.x, b.min.y, b.min.z].map(f32_down),
        [b.max.x, b.max.y, b.max.z].map(f32_up),
    )
}

#[inline]
fn overlaps_f32(lo: &[f32; 3], hi: &[f32; 3], e: &Entry) -> bool {
    e.lo[0] <= hi[0]
        && lo[0] <= e.hi[0]
        && e.lo[1] <= hi[1]
        && lo[1] <= e.hi[1]
        && e.lo[2] <= hi[2]
        && lo[2] <= e.hi[2]
}

/// Face ids (`u32`) bucketed by the grid cells their boxes overlap, with each face's box and
/// corners as of its insertion.
///
/// Cells are hashed into a power-of-two table of buckets (no map, no bounds needed); two cells
/// sharing a bucket only add candidates, which the stored boxes filter out.
#[derive(Debug)]
pub(crate) struct FaceGrid {
    inv_cell: f64,
    buckets: Vec<Vec<Entry>>,
    mask: usize,
    slots: Vec<Slot>,
    boxes: Vec<Aabb>,
    corners: Vec<[u32; 3]>,
    oversized: Vec<u32>,
    /// Per-face query stamp, so a face listed in several cells is visited once per query.
    seen: Vec<u32>,
    query: u32,
}

/// The bucket of `cell` in a table of `mask + 1` buckets.
#[inline]
fn bucket_of(mask: usize, [x, y, z]: Cell) -> usize {
    let h = (x as u32 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u32 as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ (z as u32 as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
    ((h ^ (h >> 29)) as usize) & mask
}

impl FaceGrid {
    /// An empty grid with cubic cells of edge `cell` (> 0) for face ids `< capacity`, sized
    /// for about `faces` faces.
    pub(crate) fn new(cell: f64, capacity: usize, faces: usize) -> FaceGrid {
        let n_buckets = (2 * faces).max(64).next_power_of_two();
        FaceGrid {
            inv_cell: 1.0 / cell,
            buckets: vec![Vec::new(); n_buckets],
            mask: n_buckets - 1,
            slots: vec![Slot::Absent; capacity],
            boxes: vec![Aabb::EMPTY; capacity],
            corners: vec![[0; 3]; capacity],
            oversized: Vec::new(),
            seen: vec![0; capacity],
            query: 0,
        }
    }

    fn cell_of(&self, x: f64) -> i32 {
        // `as` saturates, so far-away or non-finite coordinates stay in range.
        (x * self.inv_cell).floor() as i32
    }

    fn range(&self, b: &Aabb) -> (Cell, Cell) {
        let lo = [b.min.x, b.min.y, b.min.z].map(|x| self.cell_of(x));
        let hi = [b.max.x, b.max.y, b.max.z].map(|x| self.cell_of(x));
        (lo, hi)
    }

    fn count(lo: Cell, hi: Cell) -> i64 {
        (0..3)
            .map(|k| (hi[k] as i64 - lo[k] as i64 + 1).max(0))
            .product()
    }

    #[inline]
    fn bucket(&self, cell: Cell) -> usize {
        bucket_of(self.mask, cell)
    }

    /// Adds face `f` with corners `corners` and box `b` (removing it first if present).
    pub(crate) fn insert(&mut self, f: u32, corners: [u32; 3], b: &Aabb) {
        self.remove(f);
        self.boxes[f as usize] = *b;
        self.corners[f as usize] = corners;
        let (lo, hi) = self.range(b);
        let (flo, fhi) = f32_box(b);
        let entry = Entry {
            face: f,
            lo: flo,
            hi: fhi,
        };
        if !b.min.is_finite() || !b.max.is_finite() || Self::count(lo, hi) > MAX_CELLS_PER_FACE {
            self.oversized.push(f);
            self.slots[f as usize] = Slot::Oversized;
            return;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let k = self.bucket([x, y, z]);
                    self.buckets[k].push(entry);
                }
            }
        }
        self.slots[f as usize] = Slot::Cells { lo, hi };
    }

    /// Removes face `f` (no-op if absent).
    pub(crate) fn remove(&mut self, f: u32) {
        match std::mem::replace(&mut self.slots[f as usize], Slot::Absent) {
            Slot::Absent => {}
            Slot::Oversized => self.oversized.retain(|&g| g != f),
            Slot::Cells { lo, hi } => {
                for x in lo[0]..=hi[0] {
                    for y in lo[1]..=hi[1] {
                        for z in lo[2]..=hi[2] {
                            let k = self.bucket([x, y, z]);
                            let list = &mut self.buckets[k];
                            if let Some(i) = list.iter().position(|g| g.face == f) {
                                list.swap_remove(i);
                            }
                        }
                    }
                }
            }
        }
        self.boxes[f as usize] = Aabb::EMPTY;
    }

    /// Calls `visit(face, its box, its corners)` once for every face whose box overlaps `b`
    /// (all faces sharing a bucket with a cell of `b`, and the oversized ones, are scanned).
    pub(crate) fn query(&mut self, b: &Aabb, mut visit: impl FnMut(u32, &Aabb, [u32; 3])) {
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.seen.fill(0);
            self.query = 1;
        }
        let stamp = self.query;
        let (lo, hi) = self.range(b);
        let (qlo, qhi) = f32_box(b);
        let (seen, boxes, corners) = (&mut self.seen, &self.boxes, &self.corners);
        let mut take = |f: u32| {
            if seen[f as usize] != stamp {
                seen[f as usize] = stamp;
                let fb = &boxes[f as usize];
                if fb.overlaps(b) {
                    visit(f, fb, corners[f as usize]);
                }
            }
        };
        if !b.min.is_finite()
            || !b.max.is_finite()
            || Self::count(lo, hi) > self.buckets.len() as i64
        {
            for list in &self.buckets {
                list.iter().for_each(|e| take(e.face));
            }
        } else {
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        for e in &self.buckets[bucket_of(self.mask, [x, y, z])] {
                            if overlaps_f32(&qlo, &qhi, e) {
                                take(e.face);
                            }
                        }
                    }
                }
            }
        }
        self.oversized.iter().for_each(|&f| take(f));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn boxed(a: f64, b: f64) -> Aabb {
        Aabb {
            min: DVec3::splat(a),
            max: DVec3::splat(b),
        }
    }

    #[test]
    fn query_finds_overlapping_faces_once_and_forgets_removed_ones() {
        let mut g = FaceGrid::new(1.0, 4, 4);
        g.insert(0, [0, 1, 2], &boxed(0.1, 0.2));
        g.insert(1, [0, 1, 2], &boxed(0.5, 2.5));
        g.insert(2, [0, 1, 2], &boxed(5.0, 5.5));
        g.insert(3, [0, 1, 2], &boxed(-100.0, 100.0)); // oversized
        let mut found = Vec::new();
        g.query(&boxed(0.0, 1.5), |f, _, _| found.push(f));
        found.sort();
        assert_eq!(found, vec![0, 1, 3]);
        g.remove(1);
        g.remove(3);
        found.clear();
        g.query(&boxed(0.0, 1.5), |f, _, _| found.push(f));
        assert_eq!(found, vec![0]);
    }
}
