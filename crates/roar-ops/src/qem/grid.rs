//! A dynamic uniform grid over face boxes: the broad phase of the self-intersection veto while
//! the mesh changes under it (a [`roar_mesh::spatial::TriangleBvh`] cannot follow faces whose
//! vertex indices change, and rebuilding it after every collapse costs O(F log F)).
//!
//! Each face is listed in every cell its box overlaps; faces spanning more than
//! [`MAX_CELLS_PER_FACE`] cells go to an always-scanned `oversized` list. Insert and remove are
//! O(cells of the face); the caller rebuilds with a coarser cell when faces have grown.

use roar_mesh::spatial::Aabb;
use std::collections::HashMap;

/// Faces overlapping more cells than this are kept in a flat list instead.
const MAX_CELLS_PER_FACE: i64 = 64;

type Cell = [i32; 3];

#[derive(Debug, Clone, Copy)]
enum Slot {
    Absent,
    Cells { lo: Cell, hi: Cell },
    Oversized,
}

/// Face ids (`u32`) bucketed by the grid cells their boxes overlap.
#[derive(Debug)]
pub(crate) struct FaceGrid {
    cell: f64,
    cells: HashMap<Cell, Vec<u32>>,
    slots: Vec<Slot>,
    oversized: Vec<u32>,
    /// Per-face query stamp, so a face listed in several cells is visited once per query.
    seen: Vec<u32>,
    query: u32,
}

impl FaceGrid {
    /// An empty grid with cubic cells of edge `cell` (> 0) for face ids `< capacity`.
    pub(crate) fn new(cell: f64, capacity: usize) -> FaceGrid {
        FaceGrid {
            cell,
            cells: HashMap::new(),
            slots: vec![Slot::Absent; capacity],
            oversized: Vec::new(),
            seen: vec![0; capacity],
            query: 0,
        }
    }

    fn cell_of(&self, x: f64) -> i32 {
        // `as` saturates, so far-away or non-finite coordinates stay in range.
        (x / self.cell).floor() as i32
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

    /// Adds face `f` with box `b` (removing it first if present).
    pub(crate) fn insert(&mut self, f: u32, b: &Aabb) {
        self.remove(f);
        let (lo, hi) = self.range(b);
        if !b.min.is_finite() || !b.max.is_finite() || Self::count(lo, hi) > MAX_CELLS_PER_FACE {
            self.oversized.push(f);
            self.slots[f as usize] = Slot::Oversized;
            return;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    self.cells.entry([x, y, z]).or_default().push(f);
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
                            if let Some(list) = self.cells.get_mut(&[x, y, z])
                                && let Some(i) = list.iter().position(|&g| g == f)
                            {
                                list.swap_remove(i);
                            }
                        }
                    }
                }
            }
        }
    }

    /// Calls `visit` once for every face that may overlap `b`: every face sharing a cell with
    /// `b`, plus every oversized face (a superset; callers run the exact test).
    pub(crate) fn query(&mut self, b: &Aabb, mut visit: impl FnMut(u32)) {
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.seen.fill(0);
            self.query = 1;
        }
        let stamp = self.query;
        let (lo, hi) = self.range(b);
        let mut take = |f: u32, seen: &mut Vec<u32>| {
            if seen[f as usize] != stamp {
                seen[f as usize] = stamp;
                visit(f);
            }
        };
        if !b.min.is_finite() || !b.max.is_finite() || Self::count(lo, hi) > self.cells.len() as i64
        {
            for list in self.cells.values() {
                for &f in list {
                    take(f, &mut self.seen);
                }
            }
        } else {
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        if let Some(list) = self.cells.get(&[x, y, z]) {
                            for &f in list {
                                take(f, &mut self.seen);
                            }
                        }
                    }
                }
            }
        }
        for &f in &self.oversized {
            take(f, &mut self.seen);
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

    #[test]
    fn query_finds_overlapping_faces_once_and_forgets_removed_ones() {
        let mut g = FaceGrid::new(1.0, 4);
        g.insert(0, &boxed(0.1, 0.2));
        g.insert(1, &boxed(0.5, 2.5));
        g.insert(2, &boxed(5.0, 5.5));
        g.insert(3, &boxed(-100.0, 100.0)); // oversized
        let mut found = Vec::new();
        g.query(&boxed(0.0, 1.5), |f| found.push(f));
        found.sort();
        assert_eq!(found, vec![0, 1, 3]);
        g.remove(1);
        g.remove(3);
        found.clear();
        g.query(&boxed(0.0, 1.5), |f| found.push(f));
        assert_eq!(found, vec![0]);
    }
}
