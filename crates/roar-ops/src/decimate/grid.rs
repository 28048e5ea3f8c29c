//! A dynamic uniform grid over face boxes: the broad phase of the self-intersection veto while
//! the mesh changes under it (a [`roar_mesh::spatial::TriangleBvh`] cannot follow faces whose
//! vertex indices change, and rebuilding it after every collapse costs O(F log F)).
//!
//! Each face is listed in every cell its box overlaps; faces spanning more than
//! [`MAX_CELLS_PER_FACE`] cells go to an always-scanned `oversized` list. Insert and remove are
//! O(cells of the face); the caller rebuilds with a coarser cell when faces have grown.
//!
//! A query touches only the buckets of its cells: every entry carries the face's corners and its
//! box (rounded outward to `f32`), so no per-face array is read, and a face listed in several
//! cells is reported once because it is reported only from one cell (see [`FaceGrid::query`]),
//! not through a per-face "seen" stamp. Those per-face reads were cache misses that made up most
//! of the query time on large meshes.

use roar_mesh::spatial::Aabb;

/// Faces overlapping more cells than this are kept in a flat list instead.
const MAX_CELLS_PER_FACE: i64 = 64;

type Cell = [i32; 3];

/// A box with `f32` corners. Made from an [`Aabb`] by rounding outward ([`Box32::around`]), so it
/// contains the original box: two such boxes overlap whenever the originals do, which makes them
/// a safe filter in front of an exact test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Box32 {
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

impl Box32 {
    /// The smallest `f32` box containing `b` (NaN coordinates stay NaN and overlap nothing, as
    /// with [`Aabb::overlaps`]).
    pub(crate) fn around(b: &Aabb) -> Box32 {
        Box32 {
            lo: [b.min.x, b.min.y, b.min.z].map(f32_down),
            hi: [b.max.x, b.max.y, b.max.z].map(f32_up),
        }
    }

    /// The smallest box containing both (NaN-free inputs).
    pub(crate) fn union(&self, o: &Box32) -> Box32 {
        Box32 {
            lo: [0, 1, 2].map(|k| self.lo[k].min(o.lo[k])),
            hi: [0, 1, 2].map(|k| self.hi[k].max(o.hi[k])),
        }
    }

    /// Whether the closed boxes share a point. (All six comparisons are evaluated, without
    /// branches: the answer is unpredictable in a bucket scan.)
    #[inline]
    pub(crate) fn overlaps(&self, o: &Box32) -> bool {
        (o.lo[0] <= self.hi[0])
            & (self.lo[0] <= o.hi[0])
            & (o.lo[1] <= self.hi[1])
            & (self.lo[1] <= o.hi[1])
            & (o.lo[2] <= self.hi[2])
            & (self.lo[2] <= o.hi[2])
    }

    fn is_finite(&self) -> bool {
        self.lo.iter().chain(&self.hi).all(|x| x.is_finite())
    }
}

/// A face listed in a bucket, with its corners, rounded box and lowest cell as of its
/// insertion (the lowest cell decides which cell reports the face in a query; stored so that a
/// query does not convert the box to cells again for every entry it meets).
#[derive(Debug, Clone, Copy)]
struct Entry {
    face: u32,
    corners: [u32; 3],
    bx: Box32,
    first: Cell,
}

#[derive(Debug, Clone, Copy)]
enum Slot {
    Absent,
    Cells { lo: Cell, hi: Cell },
    Oversized,
}

/// Face ids (`u32`) bucketed by the grid cells their boxes overlap, with each face's box and
/// corners as of its insertion.
///
/// Cells are hashed into a power-of-two table of buckets (no map, no bounds needed); two cells
/// sharing a bucket only add candidates, which the stored boxes filter out. A face is listed at
/// most once per bucket, even when several of its cells share the bucket.
#[derive(Debug)]
pub(crate) struct FaceGrid {
    inv_cell: f64,
    buckets: Vec<Vec<Entry>>,
    mask: usize,
    slots: Vec<Slot>,
    oversized: Vec<Entry>,
}

/// The bucket of `cell` in a table of `mask + 1` buckets: a hash of the cell's column `(x, y)`
/// plus `z`, so the cells of a column run, which every loop over a cell range visits innermost,
/// lie in consecutive buckets. Their list headers then share cache lines, where a hash of all
/// three coordinates made each cell of a query a separate cache miss. (Which cells share a bucket
/// changes only how many entries a scan filters out, never an answer.)
#[inline]
fn bucket_of(mask: usize, [x, y, z]: Cell) -> usize {
    let h = (x as u32 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u32 as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    ((h ^ (h >> 29)).wrapping_add(z as u32 as u64) as usize) & mask
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
            oversized: Vec::new(),
        }
    }

    /// `floor(x / cell)`, saturated to `i32` (NaN gives 0), like `(x * inv_cell).floor() as i32`
    /// but without a call to `floor`, which is not inlined on baseline x86-64.
    #[inline]
    fn cell_of(&self, x: f32) -> i32 {
        let v = x as f64 * self.inv_cell;
        let t = v as i32;
        t.saturating_sub(i32::from(t as f64 > v))
    }

    /// The cells of `b`: every cell is computed from the rounded box, so a face and a query
    /// whose rounded boxes overlap have overlapping cell ranges (`cell_of` is monotone).
    #[inline]
    fn range(&self, b: &Box32) -> (Cell, Cell) {
        (b.lo.map(|x| self.cell_of(x)), b.hi.map(|x| self.cell_of(x)))
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
        let bx = Box32::around(b);
        let (lo, hi) = self.range(&bx);
        let entry = Entry {
            face: f,
            corners,
            bx,
            first: lo,
        };
        if !bx.is_finite() || Self::count(lo, hi) > MAX_CELLS_PER_FACE {
            self.oversized.push(entry);
            self.slots[f as usize] = Slot::Oversized;
            return;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let k = self.bucket([x, y, z]);
                    let list = &mut self.buckets[k];
                    // This insert's own entries are the last ones pushed to a bucket.
                    if list.last().is_none_or(|e| e.face != f) {
                        list.push(entry);
                    }
                }
            }
        }
        self.slots[f as usize] = Slot::Cells { lo, hi };
    }

    /// The same as [`Self::insert`] (afterwards every query reports the same faces with the same
    /// boxes and corners), but when `f` is listed and its new box covers the same cells as its
    /// old one, its entries are overwritten where they are: one scan of each of its buckets,
    /// where a remove and an insert scan each bucket and then push to it again. After a collapse
    /// most faces around the kept vertex move by less than a cell. (Only the order of entries in
    /// a bucket can differ from [`Self::insert`], which no query answer depends on.)
    pub(crate) fn update(&mut self, f: u32, corners: [u32; 3], b: &Aabb) {
        let bx = Box32::around(b);
        let (lo, hi) = self.range(&bx);
        let same_cells = matches!(
            self.slots[f as usize],
            Slot::Cells { lo: old_lo, hi: old_hi } if old_lo == lo && old_hi == hi
        );
        if !same_cells || !bx.is_finite() {
            self.insert(f, corners, b);
            return;
        }
        let entry = Entry {
            face: f,
            corners,
            bx,
            first: lo,
        };
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let k = self.bucket([x, y, z]);
                    if let Some(e) = self.buckets[k].iter_mut().find(|e| e.face == f) {
                        *e = entry;
                    }
                }
            }
        }
    }

    /// Removes face `f` (no-op if absent).
    pub(crate) fn remove(&mut self, f: u32) {
        match std::mem::replace(&mut self.slots[f as usize], Slot::Absent) {
            Slot::Absent => {}
            Slot::Oversized => self.oversized.retain(|e| e.face != f),
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
    }

    /// Reads the first entry of every bucket of the cells `lo..=hi`, without using it, so that
    /// the cache misses of a query's buckets (most of its time on large meshes) overlap, where
    /// the scan, whose branches depend on each entry, meets them one at a time.
    #[inline]
    fn touch(&self, lo: Cell, hi: Cell) {
        let mut sink = 0u32;
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    if let Some(e) = self.buckets[self.bucket([x, y, z])].first() {
                        sink ^= e.face;
                    }
                }
            }
        }
        std::hint::black_box(sink);
    }

    /// Calls `visit(face, its rounded box, its corners)` exactly once for every face whose
    /// rounded box overlaps `b` (and for no other face).
    ///
    /// Each face is reported from one cell only: the lowest cell (per axis) shared by its cell
    /// range and the query's, which lies in both ranges whenever the boxes overlap. A bucket is
    /// scanned once per query cell mapping to it, and lists the face at most once.
    pub(crate) fn query(&self, b: &Box32, mut visit: impl FnMut(u32, &Box32, [u32; 3])) {
        let (lo, hi) = self.range(b);
        if !b.is_finite() || Self::count(lo, hi) > self.buckets.len() as i64 {
            // Every face is listed in the bucket of its lowest cell.
            for (k, list) in self.buckets.iter().enumerate() {
                for e in list {
                    if b.overlaps(&e.bx) && self.bucket(e.first) == k {
                        visit(e.face, &e.bx, e.corners);
                    }
                }
            }
        } else {
            self.touch(lo, hi);
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        for e in &self.buckets[self.bucket([x, y, z])] {
                            if b.overlaps(&e.bx) {
                                let own = [0, 1, 2].map(|k| e.first[k].max(lo[k]));
                                if own == [x, y, z] {
                                    visit(e.face, &e.bx, e.corners);
                                }
                            }
                        }
                    }
                }
            }
        }
        for e in &self.oversized {
            if b.overlaps(&e.bx) {
                visit(e.face, &e.bx, e.corners);
            }
        }
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

    fn found(g: &FaceGrid, b: &Aabb) -> Vec<u32> {
        let mut found = Vec::new();
        g.query(&Box32::around(b), |f, _, _| found.push(f));
        found.sort();
        found
    }

    #[test]
    fn query_finds_overlapping_faces_once_and_forgets_removed_ones() {
        let mut g = FaceGrid::new(1.0, 4, 4);
        g.insert(0, [0, 1, 2], &boxed(0.1, 0.2));
        g.insert(1, [0, 1, 2], &boxed(0.5, 2.5));
        g.insert(2, [0, 1, 2], &boxed(5.0, 5.5));
        g.insert(3, [0, 1, 2], &boxed(-100.0, 100.0)); // oversized
        assert_eq!(found(&g, &boxed(0.0, 1.5)), vec![0, 1, 3]);
        // A query box spanning more cells than there are buckets scans every bucket.
        assert_eq!(found(&g, &boxed(-50.0, 50.0)), vec![0, 1, 2, 3]);
        g.remove(1);
        g.remove(3);
        assert_eq!(found(&g, &boxed(0.0, 1.5)), vec![0]);
    }

    /// Every query answer after `update` equals the answer after `insert`, for moves that keep
    /// a face's cells, move it to other cells, make it oversized and bring it back.
    #[test]
    fn update_answers_like_insert() {
        let mut seed = 0x1234_5678_9ABC_DEF1u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let random_box = |next: &mut dyn FnMut() -> f64| {
            let lo = DVec3::new(next(), next(), next()) * 6.0 - DVec3::splat(3.0);
            let size = if next() < 0.05 { 40.0 } else { 0.05 + next() };
            Aabb {
                min: lo,
                max: lo + DVec3::new(next(), next(), next()) * size,
            }
        };
        let n = 60;
        // 64 buckets for faces of up to ~3³ cells: many cells share buckets.
        let (mut a, mut b) = (FaceGrid::new(0.5, n, 1), FaceGrid::new(0.5, n, 1));
        let mut boxes: Vec<Aabb> = (0..n).map(|_| random_box(&mut next)).collect();
        for (f, bx) in boxes.iter().enumerate() {
            a.insert(f as u32, [f as u32, 0, 0], bx);
            b.insert(f as u32, [f as u32, 0, 0], bx);
        }
        let mut in_place = 0;
        for round in 0..400u32 {
            let f = (next() * n as f64) as usize;
            let old = boxes[f];
            boxes[f] = if next() < 0.7 {
                // A small move: usually the same cells.
                let d = DVec3::new(next(), next(), next()) * 0.02;
                Aabb {
                    min: old.min + d,
                    max: old.max + d,
                }
            } else {
                random_box(&mut next)
            };
            let same = a.range(&Box32::around(&old)) == a.range(&Box32::around(&boxes[f]));
            in_place += usize::from(same);
            a.update(f as u32, [f as u32, round, 1], &boxes[f]);
            b.insert(f as u32, [f as u32, round, 1], &boxes[f]);
            let q = random_box(&mut next);
            let answers = |g: &FaceGrid| {
                let mut found = Vec::new();
                g.query(&Box32::around(&q), |f, bx, c| found.push((f, *bx, c)));
                found.sort_by_key(|&(f, _, _)| f);
                found
            };
            assert_eq!(answers(&a), answers(&b), "round {round}");
        }
        assert!(in_place > 100, "only {in_place} in-place updates");
    }

    #[test]
    fn query_reports_each_face_once_even_when_its_cells_share_buckets() {
        // 64 buckets and faces spanning up to 4³ cells: many cells of one face share a bucket.
        let mut g = FaceGrid::new(0.25, 40, 1);
        let faces: Vec<Aabb> = (0..40)
            .map(|i| {
                let a = 0.37 * i as f64 - 3.0;
                Aabb {
                    min: DVec3::new(a, -a, 0.5 * a),
                    max: DVec3::new(a + 0.9, -a + 0.6, 0.5 * a + 0.8),
                }
            })
            .collect();
        for (f, b) in faces.iter().enumerate() {
            g.insert(f as u32, [0, 1, 2], b);
        }
        for q in [boxed(-1.0, 1.0), boxed(-3.0, 0.0), boxed(0.3, 0.4)] {
            let expected: Vec<u32> = (0..40)
                .filter(|&f| Box32::around(&faces[f as usize]).overlaps(&Box32::around(&q)))
                .collect();
            assert_eq!(found(&g, &q), expected);
        }
    }
}
