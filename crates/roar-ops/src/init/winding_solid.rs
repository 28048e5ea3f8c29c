//! Inside versus outside despite holes: the generalized winding number of the soup decides which
//! voxels the exterior flood reached only through a puncture.
//!
//! The flood fill of module `solid` calls every voxel the grid border reaches *exterior*. A closed
//! surface with punctures (missing faces wider than the one-voxel gap closing) lets the flood into
//! its inside, and the init then becomes a thin shell around the surface with one handle per
//! puncture. The generalized winding number `w` of the soup (Jacobson et al. 2013; the fast
//! evaluation of `roar_mesh::spatial::WindingNumber`) tells the two apart: inside a punctured
//! closed, consistently oriented surface `w` is near 1 away from the holes (a hole only removes
//! its own solid angle), outside it is 0, and across a hole it falls from 1 to 0, so the level
//! set `w = ½` caps the hole. Inside a real tunnel (a torus's hole, a mug's handle) `w` is 0, so
//! tunnels stay open. The soup is first turned piece by piece to face outward (module `orient`),
//! since a piece stored inside out subtracts where it should add.
//!
//! **How the rules combine.** The winding number only ever *adds* solid, in three steps:
//! 1. every exterior voxel whose centre has `w` above half the threshold turns solid, and the
//!    exterior is flooded again from the border, so the pockets this cuts off turn solid too;
//! 2. the exterior takes back, lowest `w` first, each of those voxels below the threshold whose
//!    opening changes no topology (a simple voxel, module `simple`): where holes are wide, `w`
//!    between two of them across a tube dips below ½, and a plain threshold at ½ cuts a tunnel
//!    there, a handle the object does not have; the opening dents the solid at each hole but
//!    cuts no tunnel, so the solid keeps the topology of the first step's, where `w` above ¼
//!    spans those gaps and a real tunnel (`w` = 0) stays open;
//! 3. each filled region whose caps are wide (below) is given back to the exterior whole: it
//!    is an opening, and the input's shell around it stays as the flood gave it. (Opening it
//!    through simple voxels only would leave plugs in it far from the input: c3d-beetle's
//!    init then lies 0.024 of its diagonal from the soup on average, against 0.01 allowed.)
//!
//! Open surfaces and zero-thickness sheets enclose nothing: one flat sheet's `w` stays inside
//! `(−½, ½)`, so it adds nothing past step 2, and the sheet keeps the shell the flood gives it.
//!
//! **Punctures, not openings.** An open surface that wraps around a volume (a cup, an open box,
//! a head open at the neck) has `w` above ½ inside too, and filling it would add a cap that is
//! not in the input. So each filled region (26-connected) is kept only if its *caps* (the
//! connected patches of its boundary towards the exterior, i.e. not against the input's shell) are
//! narrow: no point of them farther than [`CapLimits::inradius`] voxels from the input's shell (a
//! hole is narrower than the object; the opening of an open box is as wide as the box), and the
//! widest at most [`CapLimits::fraction`] of the region's boundary (the thin layer on the
//! concave side of a curved sheet, where `w` is just above ½, is capped on almost all its
//! boundary), or, if wider, one hole of several: at most [`SHARED_CAP_SHARE`] of all its caps
//! and [`SHARED_CAP_FRACTION`] of its boundary (a container has one opening, a surface punctured
//! all over many holes, nearby ones sharing one wide cap of voxels). docs/method.md gives the
//! figures that chose the defaults.
//!
//! **Where the rule fails.** (a) A piece seen equally from both sides (module `orient`) keeps
//! the orientation it came with; if it was stored inside out, `w` inside is lower there. (b)
//! Several open sheets stacked with the same orientation add up past the threshold between
//! them; that gap fills if it is closed all round but for small caps. (c) A closed surface with
//! one hole wider than the cap limits (a torn-off side) stays hollow, and an open surface whose
//! opening is narrow against its size (a bottle) closes. (d) Where holes leave `w` above ¼ across
//! a real tunnel (a hole at the rim of a handle narrower than the hole), the tunnel closes. (e)
//! Holes narrower than a voxel are closed by the flood's gap closing already; the winding rule
//! adds nothing there.

use super::grid::{EXTERIOR, Grid, SOLID};
use super::orient::{self, Orientation};
use super::sight::{DepthMap, ScannerView, hidden_from_every_scanner};
use super::{simple, solid};
use glam::DVec3;
use roar_mesh::spatial::WindingNumber;
use std::collections::{HashMap, HashSet};

/// How narrow a filled region's caps must be for it to stay filled (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CapLimits {
    /// Most faces of the widest cap, as a fraction of the region's boundary faces (wider ones
    /// may pass as one hole of several, [`SHARED_CAP_SHARE`]).
    pub fraction: f64,
    /// Most 26-steps from a cap voxel to the nearest one touching the input's shell.
    pub inradius: f64,
}

impl CapLimits {
    /// Limits every region passes.
    #[cfg(test)]
    const NONE: CapLimits = CapLimits {
        fraction: 1.0,
        inradius: f64::INFINITY,
    };
}

/// A region whose widest cap is wider than [`CapLimits::fraction`] stays filled still if that
/// cap holds at most this share of all its caps (a punctured surface has many holes, a
/// container one opening) ...
const SHARED_CAP_SHARE: f64 = 0.75;

/// ... and covers at most this fraction of its boundary.
const SHARED_CAP_FRACTION: f64 = 0.3;

/// What [`fill_enclosed`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct EnclosedFill {
    /// Winding numbers evaluated (lattice points and voxels, see [`winding_above`]).
    pub evaluated: usize,
    /// Of those, the ones hidden from every scanner (module `sight`; 0 without scanner views).
    pub hidden: usize,
    /// Voxels that turned solid (above the threshold, or cut off from the border by those).
    pub filled: usize,
    /// Regions above the threshold left exterior because their cap was too wide.
    pub left_open: usize,
    /// How the soup was turned before its winding number was taken (module `orient`).
    pub orientation: Orientation,
}

/// Turns solid the exterior voxels of `state` that the soup encloses (module doc): every one
/// whose centre has a winding number (of `soup`) above `threshold / 2` or that is hidden from
/// every one of `views` (module `sight`) turns solid, with the pockets this cuts off from the
/// border; then the exterior takes back, lowest winding number first, every such voxel below
/// `threshold` whose opening changes no topology ([`open_without_tunnels`]); and each region
/// left filled whose caps are not within `caps` is given back to the exterior.
/// Only voxels inside the soup's bounding box are evaluated: outside it the winding number of a
/// closed surface is 0 and that of open sheets stays within `(−½, ½)`.
///
/// Promises: no solid voxel of `state` turns exterior; the exterior stays exactly the set of
/// voxels the border reaches through exterior voxels.
pub(crate) fn fill_enclosed(
    grid: &Grid,
    state: &mut Vec<u8>,
    soup: &[[DVec3; 3]],
    threshold: f64,
    caps: CapLimits,
    views: &[ScannerView],
) -> EnclosedFill {
    // Long triangles bisected: the winding number is the same (solid angles add up), but a long
    // triangle sits in a wide leaf of the fast winding number's tree, which every query near it
    // must evaluate exactly, while short ones are summed by the far-field expansion.
    let (oriented, orientation) = orient::orient_patches(soup);
    let (positions, triangles) = super::soup::split_long_edges(&oriented, 4.0 * grid.voxel_size);
    let Ok(winding) = WindingNumber::build(&positions, &triangles) else {
        // Unreachable: the indices above are in range by construction.
        return EnclosedFill::default();
    };
    let (lo, hi) = bounds(&positions);
    let center = |idx: usize| grid.centre(grid.coords(idx));
    let candidates: Vec<usize> = (0..grid.len())
        .filter(|&idx| state[idx] == EXTERIOR && !grid.on_border(grid.coords(idx)))
        .filter(|&idx| {
            let c = center(idx);
            c.cmpge(lo).all() && c.cmple(hi).all()
        })
        .collect();
    let low = 0.5 * threshold;
    let (values, evaluated) = winding_values(grid, state, &winding, &candidates, low);
    let maps: Vec<DepthMap> = views
        .iter()
        .filter_map(|view| DepthMap::new(view, soup, grid.voxel_size))
        .collect();
    // The winding number of every candidate (0 where settled below `low`), 1 where hidden from
    // every scanner, so those are never opened again.
    let mut w = vec![0.0f32; grid.len()];
    let mut blocked: Vec<u8> = state.iter().map(|&s| u8::from(s == SOLID)).collect();
    let mut above = 0;
    let mut hidden = 0;
    for (&idx, &value) in candidates.iter().zip(&values) {
        let is_hidden = hidden_from_every_scanner(&maps, center(idx));
        hidden += usize::from(is_hidden);
        w[idx] = if is_hidden { 1.0 } else { value as f32 };
        if is_hidden || value > low {
            blocked[idx] = 1;
            above += 1;
        }
    }
    if above == 0 {
        return EnclosedFill {
            evaluated,
            orientation,
            ..EnclosedFill::default()
        };
    }
    let before = state.iter().filter(|&&s| s == SOLID).count();
    let mut flooded = solid::flood_exterior(grid, &blocked);
    let threshold = threshold as f32;
    open_without_tunnels(grid, state, &mut flooded, &w, |idx| w[idx] < threshold);
    let (wide, left_open) = wide_cap_regions(grid, state, &flooded, caps);
    // A wide region's voxels with no path to its caps (a part joined to the rest by an edge or
    // a corner only) stay solid: the exterior is one flood from the border.
    let blocked: Vec<u8> = (0..grid.len())
        .map(|idx| u8::from(flooded[idx] == SOLID && !wide[idx]))
        .collect();
    *state = solid::flood_exterior(grid, &blocked);
    let after = state.iter().filter(|&&s| s == SOLID).count();
    EnclosedFill {
        evaluated,
        hidden,
        filled: after - before,
        left_open,
        orientation,
    }
}

/// Gives back to the exterior of `after` the voxels filled since `before` (exterior there,
/// solid here) that `may_open` allows, lowest winding number `w` first, each only when it is
/// simple ([`simple::is_simple`]): the exterior dents the fill where a hole lets it in, but
/// cuts no tunnel through it, so two holes facing each other across a tube do not make a
/// handle. A voxel refused now is tried again when a neighbour opens.
///
/// Promises: only filled voxels change; the exterior stays connected to the border.
fn open_without_tunnels(
    grid: &Grid,
    before: &[u8],
    after: &mut [u8],
    w: &[f32],
    may_open: impl Fn(usize) -> bool,
) {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let filled = |idx: usize, after: &[u8]| before[idx] == EXTERIOR && after[idx] == SOLID;
    // Keys order by winding number, then index (deterministic); w ≥ 0 here, so its bits sort.
    let key = |idx: usize| Reverse((w[idx].max(0.0).to_bits(), idx));
    let mut heap = BinaryHeap::new();
    let push_neighbours = |idx: usize, after: &[u8], heap: &mut BinaryHeap<_>| {
        for n in solid::face_neighbours(grid, idx).into_iter().flatten() {
            if filled(n, after) && may_open(n) {
                heap.push(key(n));
            }
        }
    };
    for idx in 0..grid.len() {
        if after[idx] == EXTERIOR {
            continue;
        }
        let touches_exterior = solid::face_neighbours(grid, idx)
            .into_iter()
            .flatten()
            .any(|n| after[n] == EXTERIOR);
        if touches_exterior && filled(idx, after) && may_open(idx) {
            heap.push(key(idx));
        }
    }
    while let Some(Reverse((_, idx))) = heap.pop() {
        if after[idx] == EXTERIOR {
            continue;
        }
        if simple::is_simple(solid::exterior_neighbours(grid, after, idx)) {
            after[idx] = EXTERIOR;
            push_neighbours(idx, after, &mut heap);
        }
    }
}

/// Cell sizes in voxels, coarse to fine, at which [`winding_values`] tries to settle candidates
/// before evaluating them one by one.
const CELL_SIZES: [usize; 3] = [8, 4, 2];

/// The winding number at the centre of each of `candidates` (exterior voxels of `state`), 0
/// for those settled below `low`; and how many winding numbers that took.
///
/// Most candidates lie far from the soup, where `w` is harmonic, changes slowly from voxel to
/// voxel and is far below `low`. So candidates are settled by cells first, coarse to fine
/// ([`CELL_SIZES`]): a cell with no solid voxel within one voxel of it (no surface near it, so
/// no jump of `w`) whose eight corners (voxel centres) all have `w < low / 2` counts as below
/// `low` throughout. The candidates left are evaluated at their own centres. Settling a cell
/// by its corners is a bet on smoothness, not a bound.
fn winding_values(
    grid: &Grid,
    state: &[u8],
    winding: &WindingNumber,
    candidates: &[usize],
    low: f64,
) -> (Vec<f64>, usize) {
    let mut settled = vec![false; candidates.len()];
    let mut evaluated = 0;
    for size in CELL_SIZES {
        let cells = grid.dims.map(|d| d.div_ceil(size));
        let cell_index = |c: [usize; 3]| c[0] + cells[0] * (c[1] + cells[1] * c[2]);
        let cell_of = |idx: usize| cell_index(grid.coords(idx).map(|x| x / size));
        // Cells within one voxel of a solid voxel: voxel x lies in the dilated span
        // [size·a − 1, size·a + size] of cells a = ⌈(x − size)/size⌉ ..= ⌊(x + 1)/size⌋.
        let mut near_solid = vec![false; cells.iter().product()];
        for idx in (0..grid.len()).filter(|&idx| state[idx] == SOLID) {
            let c = grid.coords(idx);
            let span = |a: usize| {
                c[a].saturating_sub(size).div_ceil(size)..=((c[a] + 1) / size).min(cells[a] - 1)
            };
            for k in span(2) {
                for j in span(1) {
                    for i in span(0) {
                        near_solid[cell_index([i, j, k])] = true;
                    }
                }
            }
        }
        let mut open_cells: Vec<usize> = (0..candidates.len())
            .filter(|&i| !settled[i])
            .map(|i| cell_of(candidates[i]))
            .filter(|&cell| !near_solid[cell])
            .collect();
        open_cells.sort_unstable();
        open_cells.dedup();
        // The corners of those cells, each evaluated once.
        let lattice = cells.map(|n| n + 1);
        let corners = |cell: usize| {
            let c = [
                cell % cells[0],
                cell / cells[0] % cells[1],
                cell / (cells[0] * cells[1]),
            ];
            (0..8).map(move |bits: usize| [0, 1, 2].map(|a| c[a] + (bits >> a & 1)))
        };
        let lattice_index = |l: [usize; 3]| l[0] + lattice[0] * (l[1] + lattice[1] * l[2]);
        let mut slot = vec![u32::MAX; lattice.iter().product()];
        let mut points = Vec::new();
        for &cell in &open_cells {
            for l in corners(cell) {
                if slot[lattice_index(l)] == u32::MAX {
                    slot[lattice_index(l)] = points.len() as u32;
                    points.push(grid.centre(l.map(|x| x * size)));
                }
            }
        }
        let values = winding.winding_numbers(&points);
        evaluated += points.len();
        let mut below = vec![false; near_solid.len()];
        for &cell in &open_cells {
            below[cell] =
                corners(cell).all(|l| values[slot[lattice_index(l)] as usize] < 0.5 * low);
        }
        for (i, &idx) in candidates.iter().enumerate() {
            settled[i] |= below[cell_of(idx)];
        }
    }
    let rest: Vec<usize> = (0..candidates.len()).filter(|&i| !settled[i]).collect();
    let points: Vec<DVec3> = rest
        .iter()
        .map(|&i| grid.centre(grid.coords(candidates[i])))
        .collect();
    let values = winding.winding_numbers(&points);
    let mut out = vec![0.0; candidates.len()];
    for (&i, &w) in rest.iter().zip(&values) {
        out[i] = w;
    }
    (out, evaluated + points.len())
}

/// The filled regions of `after` (26-connected voxels exterior in `before`, solid in `after`)
/// whose caps are not within `caps`, as a mask over the grid, and how many there are. A
/// region's boundary is its voxel faces towards voxels outside it: *covered* where the
/// neighbour was solid already (the input's shell), *cap* where it is exterior still. A
/// puncture's cap is a narrow patch, one of several; the opening of an open surface (an open
/// box) is one wide patch. Regions are 26-connected so that the small pockets the opening
/// leaves beside a region, joined to it by an edge or a corner, are judged with it.
fn wide_cap_regions(
    grid: &Grid,
    before: &[u8],
    after: &[u8],
    caps: CapLimits,
) -> (Vec<bool>, usize) {
    let is_filled = |idx: usize| before[idx] == EXTERIOR && after[idx] == SOLID;
    let mut seen = vec![false; grid.len()];
    let mut wide = vec![false; grid.len()];
    let mut count = 0;
    for start in 0..grid.len() {
        if seen[start] || !is_filled(start) {
            continue;
        }
        seen[start] = true;
        let mut region = vec![start];
        // Exterior voxels across the cap, each with the cap faces it shares with the region.
        let mut across: HashMap<usize, usize> = HashMap::new();
        let mut boundary = 0;
        let mut next = 0;
        while next < region.len() {
            let idx = region[next];
            next += 1;
            for n in neighbours26(grid, idx) {
                if is_filled(n) && !seen[n] {
                    seen[n] = true;
                    region.push(n);
                }
            }
            for n in solid::face_neighbours(grid, idx).into_iter().flatten() {
                if is_filled(n) {
                    continue;
                }
                boundary += 1;
                if after[n] == EXTERIOR {
                    *across.entry(n).or_default() += 1;
                }
            }
        }
        let widest = widest_cap(grid, &across) as f64;
        let cap_faces: usize = across.values().sum();
        let boundary = boundary as f64;
        let one_of_several = widest <= SHARED_CAP_SHARE * cap_faces as f64
            && widest <= caps.fraction.max(SHARED_CAP_FRACTION) * boundary;
        let too_wide = !(widest <= caps.fraction * boundary || one_of_several)
            || cap_inradius(grid, before, &across) as f64 > caps.inradius;
        if too_wide {
            for idx in region {
                wide[idx] = true;
            }
            count += 1;
        }
    }
    (wide, count)
}

/// How wide the widest opening of `across` (the exterior voxels across a region's caps) is:
/// the most 26-steps, within `across`, from a voxel of it to the nearest one touching the
/// input's shell (solid in `before`); `usize::MAX` when a patch touches no shell.
fn cap_inradius(grid: &Grid, before: &[u8], across: &HashMap<usize, usize>) -> usize {
    let mut depth: HashMap<usize, usize> = HashMap::with_capacity(across.len());
    let mut frontier: Vec<usize> = across
        .keys()
        .copied()
        .filter(|&idx| neighbours26(grid, idx).any(|n| before[n] == SOLID))
        .collect();
    frontier.sort_unstable();
    for &idx in &frontier {
        depth.insert(idx, 0);
    }
    let mut level = 0;
    while !frontier.is_empty() {
        level += 1;
        let mut next = Vec::new();
        for &idx in &frontier {
            for n in neighbours26(grid, idx) {
                if across.contains_key(&n) && !depth.contains_key(&n) {
                    depth.insert(n, level);
                    next.push(n);
                }
            }
        }
        frontier = next;
    }
    if depth.len() < across.len() {
        return usize::MAX;
    }
    depth.values().copied().max().unwrap_or(0)
}

/// The cap faces of the largest patch of `across` (exterior voxels with their cap-face counts),
/// patches being its 26-connected groups of voxels.
fn widest_cap(grid: &Grid, across: &HashMap<usize, usize>) -> usize {
    let mut done = HashSet::with_capacity(across.len());
    let mut widest = 0;
    for &start in across.keys() {
        if !done.insert(start) {
            continue;
        }
        let mut stack = vec![start];
        let mut faces = 0;
        while let Some(idx) = stack.pop() {
            faces += across[&idx];
            for n in neighbours26(grid, idx) {
                if across.contains_key(&n) && done.insert(n) {
                    stack.push(n);
                }
            }
        }
        widest = widest.max(faces);
    }
    widest
}

/// The voxels sharing a face, an edge or a corner with voxel `idx`, inside the grid.
fn neighbours26(grid: &Grid, idx: usize) -> impl Iterator<Item = usize> + '_ {
    let c = grid.coords(idx).map(|x| x as i64);
    (0..27).filter(|&d| d != 13).filter_map(move |d| {
        let n = [c[0] + d % 3 - 1, c[1] + d / 3 % 3 - 1, c[2] + d / 9 - 1];
        let inside = n
            .iter()
            .zip(grid.dims)
            .all(|(&x, len)| (0..len as i64).contains(&x));
        inside.then(|| grid.index(n[0] as usize, n[1] as usize, n[2] as usize))
    })
}

fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The six faces of the box `[lo, hi]` as outward triangles, optionally without the +z face.
    fn box_soup(lo: DVec3, hi: DVec3, open_top: bool) -> Vec<[DVec3; 3]> {
        let c = |x: usize, y: usize, z: usize| {
            DVec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z])
        };
        let quads = [
            ([c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)], false), // -z
            ([c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)], true),  // +z
            ([c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)], false), // -y
            ([c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)], false), // +y
            ([c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)], false), // -x
            ([c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)], false), // +x
        ];
        let mut soup = Vec::new();
        for (q, top) in quads {
            if top && open_top {
                continue;
            }
            soup.push([q[0], q[1], q[2]]);
            soup.push([q[0], q[2], q[3]]);
        }
        soup
    }

    fn flooded(grid: &Grid, soup: &[[DVec3; 3]]) -> Vec<u8> {
        let marked = super::super::voxelize::mark_surface_voxels(grid, soup);
        solid::flood_exterior(grid, &marked)
    }

    #[test]
    fn an_open_topped_box_fills_and_a_closed_box_is_unchanged() {
        let grid = Grid::around(DVec3::ZERO, DVec3::ONE, 12, 3);
        let open = box_soup(DVec3::ZERO, DVec3::ONE, true);
        let mut state = flooded(&grid, &open);
        let solid_before = state.iter().filter(|&&s| s == SOLID).count();
        let fill = fill_enclosed(&grid, &mut state, &open, 0.6, CapLimits::NONE, &[]);
        assert!(fill.filled > 0);
        // The inside of the cup (winding number about 0.8 at its centre) is solid now.
        let mid = grid.to_grid(DVec3::new(0.5, 0.5, 0.3)).floor();
        let idx = grid.index(mid.x as usize, mid.y as usize, mid.z as usize);
        assert_eq!(state[idx], SOLID);
        assert_eq!(
            state.iter().filter(|&&s| s == SOLID).count(),
            solid_before + fill.filled
        );

        let closed = box_soup(DVec3::ZERO, DVec3::ONE, false);
        let mut state = flooded(&grid, &closed);
        let reference = state.clone();
        let fill = fill_enclosed(&grid, &mut state, &closed, 0.6, CapLimits::NONE, &[]);
        assert_eq!(fill.filled, 0);
        assert_eq!(state, reference);
    }

    #[test]
    fn a_wide_opening_stays_open_and_a_puncture_closes() {
        let grid = Grid::around(DVec3::ZERO, DVec3::ONE, 24, 3);
        let defaults = CapLimits {
            fraction: super::super::ENCLOSURE_MAX_CAP_FRACTION,
            inradius: super::super::ENCLOSURE_MAX_CAP_WIDTH * 24.0,
        };
        // The open top's centre is half the box away from the walls: twice the limit.
        let open = box_soup(DVec3::ZERO, DVec3::ONE, true);
        let mut state = flooded(&grid, &open);
        let reference = state.clone();
        let fill = fill_enclosed(&grid, &mut state, &open, 0.6, defaults, &[]);
        assert_eq!((fill.filled, fill.left_open), (0, 1));
        assert_eq!(state, reference);
        // A closed box whose top lost the two triangles of one small square (wider than the
        // flood's gap closing): the flood enters, the rule closes the puncture again.
        let mut punctured = box_soup(DVec3::ZERO, DVec3::ONE, true);
        let c = |x: f64, y: f64| DVec3::new(x, y, 1.0);
        let (a, b) = (0.3, 0.55);
        let mut top = Vec::new();
        for (x0, x1) in [(0.0, a), (a, b), (b, 1.0)] {
            for (y0, y1) in [(0.0, a), (a, b), (b, 1.0)] {
                if x0 == a && y0 == a {
                    continue;
                }
                top.push([c(x0, y0), c(x1, y0), c(x1, y1)]);
                top.push([c(x0, y0), c(x1, y1), c(x0, y1)]);
            }
        }
        punctured.extend(top);
        let mut state = flooded(&grid, &punctured);
        let fill = fill_enclosed(&grid, &mut state, &punctured, 0.6, defaults, &[]);
        assert!(fill.filled > 0 && fill.left_open == 0, "{fill:?}");
        let mid = grid.to_grid(DVec3::splat(0.5)).floor();
        assert_eq!(
            state[grid.index(mid.x as usize, mid.y as usize, mid.z as usize)],
            SOLID
        );
    }

    /// The unit box whose top lacks the squares `[x, x + 0.45] × [y, y + 0.45]` at `corners`.
    fn box_with_holes(corners: &[(f64, f64)]) -> Vec<[DVec3; 3]> {
        let mut soup = box_soup(DVec3::ZERO, DVec3::ONE, true);
        let c = |x: f64, y: f64| DVec3::new(x, y, 1.0);
        let cuts = [0.0, 0.02, 0.47, 0.53, 0.98, 1.0];
        for (x0, x1) in cuts.iter().zip(&cuts[1..]) {
            for (y0, y1) in cuts.iter().zip(&cuts[1..]) {
                if corners.contains(&(*x0, *y0)) {
                    continue;
                }
                soup.push([c(*x0, *y0), c(*x1, *y0), c(*x1, *y1)]);
                soup.push([c(*x0, *y0), c(*x1, *y1), c(*x0, *y1)]);
            }
        }
        soup
    }

    #[test]
    fn one_wide_hole_stays_open_and_several_close() {
        // Each hole is about 3.4 % of the inside's boundary, wider than the 2 % of the defaults,
        // and narrow enough for the width limit (5.4 of its 6 voxels).
        let grid = Grid::around(DVec3::ZERO, DVec3::ONE, 24, 3);
        let defaults = CapLimits {
            fraction: super::super::ENCLOSURE_MAX_CAP_FRACTION,
            inradius: super::super::ENCLOSURE_MAX_CAP_WIDTH * 24.0,
        };
        let mid = grid.to_grid(DVec3::splat(0.5)).floor();
        let mid = grid.index(mid.x as usize, mid.y as usize, mid.z as usize);
        // One hole: the opening of a container.
        let one = box_with_holes(&[(0.02, 0.02)]);
        let mut state = flooded(&grid, &one);
        let reference = state.clone();
        let fill = fill_enclosed(&grid, &mut state, &one, 0.5, defaults, &[]);
        assert_eq!((fill.filled, fill.left_open), (0, 1), "{fill:?}");
        assert_eq!(state, reference);
        // Four holes alike, a quarter of the caps each: a punctured surface.
        let four = box_with_holes(&[(0.02, 0.02), (0.02, 0.53), (0.53, 0.02), (0.53, 0.53)]);
        let mut state = flooded(&grid, &four);
        let fill = fill_enclosed(&grid, &mut state, &four, 0.5, defaults, &[]);
        assert!(fill.filled > 0 && fill.left_open == 0, "{fill:?}");
        assert_eq!(state[mid], SOLID);
    }

    #[test]
    fn cells_settle_only_voxels_below_the_low_mark() {
        // Two boxes open on one side and empty space between them: every candidate either
        // gets its own winding number or is settled where that number is below `low`, with
        // far fewer evaluations than candidates.
        let mut soup = box_soup(DVec3::ZERO, DVec3::ONE, true);
        soup.extend(box_soup(DVec3::splat(2.0), DVec3::splat(3.0), false).split_off(2));
        let (positions, triangles) = super::super::soup::split_long_edges(&soup, 0.1);
        let winding = WindingNumber::build(&positions, &triangles).unwrap();
        let grid = Grid::around(DVec3::ZERO, DVec3::splat(3.0), 60, 3);
        let state = flooded(&grid, &soup);
        let candidates: Vec<usize> = (0..grid.len()).filter(|&i| state[i] == EXTERIOR).collect();
        for low in [0.25, 0.35, 0.45] {
            let (values, evaluated) = winding_values(&grid, &state, &winding, &candidates, low);
            let mut settled = 0;
            for (&i, &value) in candidates.iter().zip(&values) {
                let exact = winding.winding_number(grid.centre(grid.coords(i)));
                if value == 0.0 && exact.abs() > 1e-12 {
                    assert!(exact < low, "settled at {exact} ≥ {low}");
                    settled += 1;
                } else {
                    assert_eq!(value, exact);
                }
            }
            assert!(
                values.iter().any(|&w| w > 0.6),
                "the cup's inside is evaluated"
            );
            assert!(settled > 0);
            assert!(
                4 * evaluated < candidates.len(),
                "{evaluated} of {}",
                candidates.len()
            );
        }
    }

    #[test]
    fn holes_facing_each_other_across_a_tube_dent_it_but_cut_no_tunnel() {
        // A square tube 4 long, 1 wide, its four sides open over a 0.9-wide window at the
        // middle: the winding number between the windows is about 0.4, below ½, so a plain
        // threshold would cut a tunnel through the tube there; the opening keeps it whole.
        let tube = box_soup(DVec3::ZERO, DVec3::new(4.0, 1.0, 1.0), false);
        let window = |t: &[DVec3; 3]| {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            (c.x - 2.0).abs() < 0.45 && [c.y, c.z].iter().any(|&v| v == 0.0 || v == 1.0)
        };
        let (positions, triangles) = super::super::soup::split_long_edges(&tube, 0.05);
        let soup: Vec<[DVec3; 3]> = triangles
            .iter()
            .map(|t| t.map(|i| positions[i as usize]))
            .filter(|t| !window(t))
            .collect();
        let flat: Vec<DVec3> = soup.iter().flatten().copied().collect();
        let ids: Vec<[u32; 3]> = (0..soup.len() as u32)
            .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
            .collect();
        let between =
            roar_mesh::spatial::exact_winding_number(&flat, &ids, DVec3::new(2.0, 0.5, 0.5));
        assert!(between < 0.5, "w between the windows {between}");
        let grid = Grid::around(DVec3::ZERO, DVec3::new(4.0, 1.0, 1.0), 64, 3);
        let mut state = flooded(&grid, &soup);
        let fill = fill_enclosed(&grid, &mut state, &soup, 0.5, CapLimits::NONE, &[]);
        assert!(fill.filled > 0);
        assert_eq!(
            euler_characteristic(&grid, &state),
            1,
            "one solid without handles"
        );
    }

    /// V − E + F − C of the union of the closed solid voxels: 1 − genus for one solid without
    /// cavities.
    fn euler_characteristic(grid: &Grid, state: &[u8]) -> i64 {
        let mut cells: [HashSet<[usize; 3]>; 4] = Default::default();
        for idx in (0..grid.len()).filter(|&i| state[i] == SOLID) {
            let c = grid.coords(idx).map(|x| 2 * x + 1);
            // The cube's closed cells, by their doubled centres: a coordinate is odd along the
            // axes the cell spans.
            for d in 0..27usize {
                let o = [d % 3, d / 3 % 3, d / 9].map(|k| k as i64 - 1);
                let cell = [0, 1, 2].map(|a| (c[a] as i64 + o[a]) as usize);
                let dimension = o.iter().filter(|&&x| x == 0).count();
                cells[dimension].insert(cell);
            }
        }
        cells[0].len() as i64 - cells[1].len() as i64 + cells[2].len() as i64
            - cells[3].len() as i64
    }

    #[test]
    fn twins_do_not_cancel_the_winding_number() {
        // The open-topped box with every face also in the other orientation, as T′ keeps
        // undecided twin pairs: the cup still fills.
        let grid = Grid::around(DVec3::ZERO, DVec3::ONE, 12, 3);
        let mut doubled = box_soup(DVec3::ZERO, DVec3::ONE, true);
        let twins: Vec<[DVec3; 3]> = doubled.iter().map(|t| [t[0], t[2], t[1]]).collect();
        doubled.extend(twins);
        let mut state = flooded(&grid, &doubled);
        assert!(fill_enclosed(&grid, &mut state, &doubled, 0.6, CapLimits::NONE, &[]).filled > 0);
    }

    #[test]
    fn splitting_long_edges_keeps_the_winding_number() {
        let soup = box_soup(DVec3::ZERO, DVec3::new(4.0, 1.0, 0.5), true);
        let (p1, t1) = super::super::soup::split_long_edges(&soup, 0.3);
        assert!(t1.len() > 10 * soup.len());
        let p0: Vec<DVec3> = soup.iter().flatten().copied().collect();
        let t0: Vec<[u32; 3]> = (0..soup.len() as u32)
            .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
            .collect();
        for q in [
            DVec3::new(2.0, 0.5, 0.25),
            DVec3::new(0.1, 0.9, 0.6),
            DVec3::new(5.0, 0.0, 0.0),
        ] {
            let (w0, w1) = (
                roar_mesh::spatial::exact_winding_number(&p0, &t0, q),
                roar_mesh::spatial::exact_winding_number(&p1, &t1, q),
            );
            assert!((w0 - w1).abs() < 1e-9, "{q}: {w0} vs {w1}");
        }
    }

    #[test]
    fn a_single_sheet_adds_no_solid() {
        // A slanted square, so that voxel centres lie inside its bounding box.
        let grid = Grid::around(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.3), 12, 3);
        let (a, b) = (DVec3::new(1.0, 0.0, 0.3), DVec3::new(1.0, 1.0, 0.3));
        let sheet = vec![[DVec3::ZERO, a, b], [DVec3::ZERO, b, DVec3::Y]];
        let mut state = flooded(&grid, &sheet);
        let reference = state.clone();
        let fill = fill_enclosed(&grid, &mut state, &sheet, 0.6, CapLimits::NONE, &[]);
        assert_eq!(fill.filled, 0);
        assert_eq!(state, reference);
    }
}
