//! One adaptive sampling of a field that every SDF stage reads (`docs/sdf.md`, "Sampling"):
//! the field's values and gradients on the corners of an octree over the bounds' cube, refined
//! where the zero set may pass, and interpolated with gradients.
//!
//! The octree starts from a coarse grid whose corners are all evaluated. A cell is split while
//! it is coarser than the finest level and the zero set may pass through it: its corners change
//! sign, or the smallest first-order distance `|f|/|∇f|` at its corners is under `band` times
//! its diagonal (which catches a plate thinner than a coarse cell, whose corners all lie
//! outside). A split evaluates the 27 corners of its 8 children, sharing the corners already
//! evaluated, so every lattice point is evaluated once, with its gradient, in batches.
//!
//! A field that cannot give its gradient cheaply ([`Sdf::has_gradient`] false: a Python
//! callable without one) is asked for values alone, and each sample's gradient is the central
//! difference of its nearest lattice neighbours along each axis (one-sided where only one
//! exists): at every level for the refinement test, and once more at the end for the earlier
//! levels' samples, from the finest neighbours the octree holds.
//!
//! Inside a leaf with corners `xᵢ`, values `fᵢ`, gradients `gᵢ` and trilinear weights `wᵢ(p)`,
//! the sampled field is `f(p) = Σ wᵢ (fᵢ + ½ gᵢ·(p − xᵢ))`, exact for quadratic fields, and its
//! gradient is the derivative of that expression. Outside the cube it is the value at the
//! nearest point of the cube plus the distance to it times the median `|∇f|` of the samples.

use std::collections::HashMap;
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;
use roar_mesh::spatial::{Aabb, Sdf, SdfCounter, SdfEvaluations};

use crate::SdfError;

/// Points per call of the field while sampling.
const BATCH: usize = 16_384;

/// Points per parallel chunk of the sampled field's own queries.
const QUERY_CHUNK: usize = 4096;

/// Lattice coordinates of the finest level are packed into 21 bits each.
const MAX_RESOLUTION: usize = (1 << 20) - 1;

/// Options of [`SampledSdf::build`].
#[derive(Clone, Debug, PartialEq)]
pub struct SampleOptions {
    /// Cells of the finest level along the cube's side; must be `coarse_resolution · 2^k`.
    pub resolution: usize,
    /// Cells of the coarse grid, every corner of which is evaluated.
    pub coarse_resolution: usize,
    /// A cell is split when a corner's first-order distance `|f|/|∇f|` is under `band` times
    /// its diagonal (or its corners change sign).
    pub band: f64,
}

impl Default for SampleOptions {
    fn default() -> Self {
        Self {
            resolution: 256,
            coarse_resolution: 16,
            band: 1.0,
        }
    }
}

impl SampleOptions {
    /// `resolution` with the coarse grid that keeps it `coarse · 2^k`: the resolution halved
    /// while it stays even and at least 32, so the coarse grid has 16 to 31 cells when the
    /// resolution allows it (256 → 16, 384 → 24).
    pub fn for_resolution(resolution: usize, band: f64) -> Self {
        let mut coarse = resolution.max(1);
        while coarse.is_multiple_of(2) && coarse >= 32 {
            coarse /= 2;
        }
        Self {
            resolution,
            coarse_resolution: coarse,
            band,
        }
    }

    /// The levels below the coarse grid, or why the options are not usable.
    fn levels(&self) -> Result<u32, SdfError> {
        let bad = |m: String| Err(SdfError::Sampling(m));
        if self.coarse_resolution == 0 || self.resolution == 0 {
            return bad("the sampling's resolutions must be positive".into());
        }
        if self.resolution > MAX_RESOLUTION {
            return bad(format!(
                "sampling resolution {} is above the largest, {MAX_RESOLUTION}",
                self.resolution
            ));
        }
        if !(self.band.is_finite() && self.band >= 0.0) {
            return bad(format!(
                "sampling band {} must be finite and not negative",
                self.band
            ));
        }
        let ratio = self.resolution / self.coarse_resolution;
        if ratio * self.coarse_resolution != self.resolution || !ratio.is_power_of_two() {
            return bad(format!(
                "sampling resolution {} is not the coarse resolution {} times a power of two",
                self.resolution, self.coarse_resolution
            ));
        }
        Ok(ratio.trailing_zeros())
    }
}

/// What [`SampledSdf::build`] did, for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct SampleStats {
    /// Points the field evaluated, each with its gradient (the lattice points sampled).
    pub field_evaluations: usize,
    /// Cells of the octree, inner and leaves.
    pub cells: usize,
    /// Leaves at the finest level (where the zero set may pass).
    pub finest_leaves: usize,
    /// Bytes of the stored samples and octree.
    pub bytes: usize,
    /// The median `|∇f|` of the samples (the slope outside the cube).
    pub median_gradient: f64,
    /// Whether the gradients are the field's own; `false`: differences of the samples.
    pub field_gradients: bool,
    /// Wall time of the sampling.
    pub seconds: f64,
}

/// One cell of the octree: its 8 corners (index `dx + 2 dy + 4 dz`) and its first child (the 8
/// children are consecutive; 0 for a leaf, as the root cells come first).
#[derive(Clone, Copy, Debug)]
struct Cell {
    corners: [u32; 8],
    children: u32,
}

/// One lattice point's value and gradient, together in one aligned block so a query reads one
/// cache line per corner.
#[derive(Clone, Copy, Debug)]
#[repr(align(32))]
struct Sample {
    value: f64,
    gradient: [f64; 3],
}

/// A field's values and gradients on an adaptive octree, interpolated with gradients
/// ([`SampledSdf::build`]). Counts its own queries, apart from the field's evaluations.
pub struct SampledSdf {
    /// The cube's lowest corner.
    origin: DVec3,
    /// Side of a finest cell.
    fine: f64,
    /// Finest cells along the cube's side.
    resolution: u32,
    /// Coarse cells along the side.
    coarse: u32,
    /// Levels below the coarse grid.
    levels: u32,
    /// The root cells (`coarse³`, x fastest) first, then every split's 8 children.
    cells: Vec<Cell>,
    samples: Vec<Sample>,
    median_gradient: f64,
    counter: SdfCounter,
}

/// The packed key of a finest-lattice point.
fn key(p: [u32; 3]) -> u64 {
    u64::from(p[0]) | (u64::from(p[1]) << 21) | (u64::from(p[2]) << 42)
}

/// Lattice points waiting for the field, and the map from every lattice point met to its
/// sample index.
struct Lattice {
    origin: DVec3,
    fine: f64,
    index: HashMap<u64, u32>,
    /// Every lattice point met, by sample index.
    coords: Vec<[u32; 3]>,
    pending: Vec<[u32; 3]>,
    count: u32,
    /// Cells of the finest level along the cube's side.
    resolution: u32,
}

impl Lattice {
    /// The sample index of lattice point `p`, queued for evaluation when it is new.
    fn corner(&mut self, p: [u32; 3]) -> u32 {
        let count = &mut self.count;
        let pending = &mut self.pending;
        let coords = &mut self.coords;
        *self.index.entry(key(p)).or_insert_with(|| {
            pending.push(p);
            coords.push(p);
            *count += 1;
            *count - 1
        })
    }

    /// Evaluates the queued points with `field`, appending to `values` and `gradients` (the
    /// field's, or differences of the samples when it has none).
    fn flush(
        &mut self,
        field: &dyn Sdf,
        values: &mut Vec<f64>,
        gradients: &mut Vec<DVec3>,
    ) -> Result<(), SdfError> {
        let with_gradient = field.has_gradient();
        let points: Vec<DVec3> = self
            .pending
            .drain(..)
            .map(|p| self.origin + self.fine * DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect();
        let start = values.len();
        values.resize(start + points.len(), 0.0);
        gradients.resize(start + points.len(), DVec3::ZERO);
        points
            .par_chunks(BATCH)
            .zip(values[start..].par_chunks_mut(BATCH))
            .zip(gradients[start..].par_chunks_mut(BATCH))
            .for_each(|((p, v), g)| {
                if with_gradient {
                    field.values_and_gradients(p, v, g);
                } else {
                    field.values(p, v);
                }
            });
        let bad =
            (start..values.len()).find(|&i| !values[i].is_finite() || !gradients[i].is_finite());
        if let Some(i) = bad {
            return Err(SdfError::Sampling(format!(
                "the field gives value {} and gradient {} at {}: not finite",
                values[i],
                gradients[i],
                points[i - start]
            )));
        }
        if !with_gradient {
            self.difference_gradients(start..values.len(), values, gradients);
        }
        Ok(())
    }

    /// Sets the gradients of the samples in `range` to differences of their nearest lattice
    /// neighbours: per axis, the smallest spacing `2^k` with a neighbour at `±2^k`; central
    /// when both exist, one-sided when one does.
    fn difference_gradients(
        &self,
        range: std::ops::Range<usize>,
        values: &[f64],
        gradients: &mut [DVec3],
    ) {
        let first = range.start;
        let neighbour = |p: [u32; 3], axis: usize, offset: i64| {
            let c = i64::from(p[axis]) + offset;
            if c < 0 || c > i64::from(self.resolution) {
                return None;
            }
            let mut q = p;
            q[axis] = c as u32;
            self.index.get(&key(q)).map(|&i| values[i as usize])
        };
        gradients[range.clone()]
            .par_iter_mut()
            .zip(&self.coords[range])
            .enumerate()
            .for_each(|(n, (g, &p))| {
                let f = values[first + n];
                for axis in 0..3 {
                    let mut spacing = 1i64;
                    g[axis] = loop {
                        if spacing > i64::from(self.resolution) {
                            break 0.0;
                        }
                        let h = spacing as f64 * self.fine;
                        match (neighbour(p, axis, -spacing), neighbour(p, axis, spacing)) {
                            (Some(a), Some(b)) => break (b - a) / (2.0 * h),
                            (Some(a), None) => break (f - a) / h,
                            (None, Some(b)) => break (b - f) / h,
                            (None, None) => spacing *= 2,
                        }
                    };
                }
            });
    }
}

impl SampledSdf {
    /// Samples `field` over the cube around `bounds` (centred on them, side their longest
    /// extent) as the module describes. Errors, before or during sampling, on options whose
    /// resolution is not `coarse · 2^k`, bounds that are not a box, or a non-finite value or
    /// gradient from the field (naming the point).
    pub fn build(
        field: &dyn Sdf,
        bounds: Aabb,
        options: &SampleOptions,
    ) -> Result<(SampledSdf, SampleStats), SdfError> {
        let started = Instant::now();
        let levels = options.levels()?;
        let extent = bounds.extent();
        if !bounds.min.is_finite() || !bounds.max.is_finite() || extent.min_element() <= 0.0 {
            return Err(SdfError::Sampling(format!(
                "bounds min {} max {} are not a box",
                bounds.min, bounds.max
            )));
        }
        let side = extent.max_element();
        let origin = bounds.center() - DVec3::splat(0.5 * side);
        let resolution = options.resolution as u32;
        let coarse = options.coarse_resolution as u32;
        let fine = side / f64::from(resolution);
        let mut lattice = Lattice {
            origin,
            fine,
            index: HashMap::new(),
            coords: Vec::new(),
            pending: Vec::new(),
            count: 0,
            resolution,
        };
        let (mut values, mut gradients) = (Vec::new(), Vec::new());
        // The coarse grid: every corner, then the root cells.
        let step = resolution / coarse;
        let mut cells = Vec::with_capacity((coarse as usize).pow(3));
        // (cell index, lowest lattice corner, side in finest cells) of the cells to test.
        let mut level: Vec<(u32, [u32; 3], u32)> = Vec::with_capacity(cells.capacity());
        for k in 0..coarse {
            for j in 0..coarse {
                for i in 0..coarse {
                    let low = [i * step, j * step, k * step];
                    let corners = cell_corners(low, step).map(|p| lattice.corner(p));
                    level.push((cells.len() as u32, low, step));
                    cells.push(Cell {
                        corners,
                        children: 0,
                    });
                }
            }
        }
        lattice.flush(field, &mut values, &mut gradients)?;
        // Where the last flush's samples start: they were differenced with every sample there.
        let mut newest = 0;
        for _ in 0..levels {
            let split: Vec<(u32, [u32; 3], u32)> = level
                .iter()
                .copied()
                .filter(|&(cell, _, size)| {
                    may_hold_zero_set(
                        &cells[cell as usize],
                        &values,
                        &gradients,
                        options.band * 3f64.sqrt() * fine * f64::from(size),
                    )
                })
                .collect();
            let mut next = Vec::with_capacity(8 * split.len());
            for (cell, low, size) in split {
                let half = size / 2;
                let mut lattice27 = [0u32; 27];
                for (n, slot) in lattice27.iter_mut().enumerate() {
                    let d = [n % 3, (n / 3) % 3, n / 9].map(|d| d as u32 * half);
                    *slot = lattice.corner([low[0] + d[0], low[1] + d[1], low[2] + d[2]]);
                }
                let first = cells.len() as u32;
                cells[cell as usize].children = first;
                for child in 0..8usize {
                    let o = [child & 1, (child >> 1) & 1, child >> 2];
                    let corners = std::array::from_fn(|c| {
                        let (x, y, z) = (o[0] + (c & 1), o[1] + ((c >> 1) & 1), o[2] + (c >> 2));
                        lattice27[x + 3 * y + 9 * z]
                    });
                    let child_low = [0, 1, 2].map(|a| low[a] + o[a] as u32 * half);
                    next.push((cells.len() as u32, child_low, half));
                    cells.push(Cell {
                        corners,
                        children: 0,
                    });
                }
            }
            newest = values.len();
            lattice.flush(field, &mut values, &mut gradients)?;
            level = next;
        }
        let field_gradients = field.has_gradient();
        if !field_gradients {
            // The earlier levels' differences again, now from the finest neighbours.
            lattice.difference_gradients(0..newest, &values, &mut gradients);
        }
        // The last level's cells are the finest ones.
        let finest_leaves = level.len();
        let mut slopes: Vec<f64> = gradients.iter().map(|g| g.length()).collect();
        let middle = slopes.len() / 2;
        let median_gradient = if slopes.is_empty() {
            1.0
        } else {
            *slopes.select_nth_unstable_by(middle, f64::total_cmp).1
        };
        let sampled = SampledSdf {
            origin,
            fine,
            resolution,
            coarse,
            levels,
            cells,
            samples: values
                .iter()
                .zip(&gradients)
                .map(|(&value, g)| Sample {
                    value,
                    gradient: g.to_array(),
                })
                .collect(),
            median_gradient,
            counter: SdfCounter::default(),
        };
        let stats = SampleStats {
            field_evaluations: sampled.samples.len(),
            cells: sampled.cells.len(),
            finest_leaves,
            bytes: sampled.bytes(),
            median_gradient,
            field_gradients,
            seconds: started.elapsed().as_secs_f64(),
        };
        Ok((sampled, stats))
    }

    /// Bytes of the stored samples and octree.
    pub fn bytes(&self) -> usize {
        self.cells.len() * std::mem::size_of::<Cell>()
            + self.samples.len() * std::mem::size_of::<Sample>()
    }

    /// The sampled field's value and gradient at `p` (the module's interpolation; outside the
    /// cube, the nearest point's value plus the distance times the median `|∇f|`).
    pub fn eval(&self, p: DVec3) -> (f64, DVec3) {
        let q = self.nearest_in_cube(p);
        let (value, mut gradient) = self.interpolate::<true>(q);
        let outside = p - q;
        let distance = outside.length();
        if distance > 0.0 && distance.is_finite() {
            let away = outside / distance;
            for axis in 0..3 {
                if outside[axis] != 0.0 {
                    gradient[axis] = self.median_gradient * away[axis];
                }
            }
        }
        (value + distance * self.median_gradient, gradient)
    }

    /// The sampled field's value at `p` (as [`SampledSdf::eval`], without the gradient).
    pub fn value(&self, p: DVec3) -> f64 {
        let q = self.nearest_in_cube(p);
        self.interpolate::<false>(q).0 + (p - q).length() * self.median_gradient
    }

    /// The point of the sampled cube nearest to `p`.
    fn nearest_in_cube(&self, p: DVec3) -> DVec3 {
        let side = self.fine * f64::from(self.resolution);
        p.clamp(self.origin, self.origin + DVec3::splat(side))
    }

    /// The leaf holding `p`, a point of the cube, with its lowest corner and side.
    fn leaf(&self, p: DVec3) -> (Cell, DVec3, f64) {
        // Finest-lattice coordinates, and the coarse cell holding them.
        let u = (p - self.origin) / self.fine;
        let step = self.resolution / self.coarse;
        let mut low = [0u32; 3];
        let mut root = [0usize; 3];
        for a in 0..3 {
            let c = ((u[a] / f64::from(step)).floor().max(0.0) as u32).min(self.coarse - 1);
            root[a] = c as usize;
            low[a] = c * step;
        }
        let n = self.coarse as usize;
        let mut cell = self.cells[root[0] + n * (root[1] + n * root[2])];
        let mut size = step;
        for _ in 0..self.levels {
            if cell.children == 0 {
                break;
            }
            size /= 2;
            let mut child = 0;
            for a in 0..3 {
                if u[a] >= f64::from(low[a] + size) {
                    child |= 1 << a;
                    low[a] += size;
                }
            }
            cell = self.cells[cell.children as usize + child];
        }
        let h = self.fine * f64::from(size);
        let base =
            self.origin + self.fine * DVec3::new(low[0].into(), low[1].into(), low[2].into());
        (cell, base, h)
    }

    /// The interpolation at `p`, a point of the cube, with its gradient when `GRADIENT` (zero
    /// otherwise: the value-only queries skip its cost).
    fn interpolate<const GRADIENT: bool>(&self, p: DVec3) -> (f64, DVec3) {
        let (cell, base, h) = self.leaf(p);
        let t = ((p - base) / h).clamp(DVec3::ZERO, DVec3::ONE);
        let mut value = 0.0;
        let mut gradient = DVec3::ZERO;
        for (c, &index) in cell.corners.iter().enumerate() {
            let bits = [c & 1, (c >> 1) & 1, c >> 2];
            // Weight factors per axis and their derivatives per unit length.
            let mut factor = [0.0; 3];
            let mut slope = [0.0; 3];
            for a in 0..3 {
                (factor[a], slope[a]) = if bits[a] == 1 {
                    (t[a], 1.0 / h)
                } else {
                    (1.0 - t[a], -1.0 / h)
                };
            }
            let w = factor[0] * factor[1] * factor[2];
            let x = base + h * DVec3::new(bits[0] as f64, bits[1] as f64, bits[2] as f64);
            let sample = &self.samples[index as usize];
            let g = DVec3::from_array(sample.gradient);
            let local = sample.value + 0.5 * g.dot(p - x);
            value += w * local;
            if GRADIENT {
                let dw = DVec3::new(
                    slope[0] * factor[1] * factor[2],
                    factor[0] * slope[1] * factor[2],
                    factor[0] * factor[1] * slope[2],
                );
                gradient += dw * local + 0.5 * w * g;
            }
        }
        (value, gradient)
    }
}

/// The 8 lattice corners of the cell at `low` of side `size`, index `dx + 2 dy + 4 dz`.
fn cell_corners(low: [u32; 3], size: u32) -> [[u32; 3]; 8] {
    std::array::from_fn(|c| {
        [
            low[0] + (c & 1) as u32 * size,
            low[1] + ((c >> 1) & 1) as u32 * size,
            low[2] + (c >> 2) as u32 * size,
        ]
    })
}

/// True when the zero set may pass through `cell`: its corners change sign (or one is zero), or
/// a corner's first-order distance `|f|/|∇f|` is under `reach`.
fn may_hold_zero_set(cell: &Cell, values: &[f64], gradients: &[DVec3], reach: f64) -> bool {
    let (mut negative, mut positive) = (false, false);
    let mut near = false;
    for &i in &cell.corners {
        let f = values[i as usize];
        negative |= f <= 0.0;
        positive |= f >= 0.0;
        near |= f.abs() < reach * gradients[i as usize].length();
    }
    (negative && positive) || near
}

impl Sdf for SampledSdf {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        self.counter.add_values(points.len());
        points
            .par_chunks(QUERY_CHUNK)
            .zip(values.par_chunks_mut(QUERY_CHUNK))
            .for_each(|(p, v)| {
                for (p, v) in p.iter().zip(v) {
                    *v = self.value(*p);
                }
            });
    }

    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        self.counter.add_gradients(points.len());
        points
            .par_chunks(QUERY_CHUNK)
            .zip(values.par_chunks_mut(QUERY_CHUNK))
            .zip(gradients.par_chunks_mut(QUERY_CHUNK))
            .for_each(|((p, v), g)| {
                for ((p, v), g) in p.iter().zip(v).zip(g) {
                    (*v, *g) = self.eval(*p);
                }
            });
    }

    /// The sampled field's own queries (the field's evaluations are [`SampleStats`]'s).
    fn evaluations(&self) -> SdfEvaluations {
        self.counter.get()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::spatial::FnSdf;

    fn cube(h: f64) -> Aabb {
        Aabb {
            min: DVec3::splat(-h),
            max: DVec3::splat(h),
        }
    }

    fn sphere(p: DVec3) -> f64 {
        p.length() - 0.6
    }

    /// A sphere with its exact gradient.
    struct Sphere {
        k: f64,
        counter: SdfCounter,
    }

    impl Sphere {
        fn new(k: f64) -> Self {
            Self {
                k,
                counter: SdfCounter::default(),
            }
        }
    }

    impl Sdf for Sphere {
        fn values(&self, points: &[DVec3], values: &mut [f64]) {
            self.counter.add_values(points.len());
            for (p, v) in points.iter().zip(values) {
                *v = self.k * sphere(*p);
            }
        }
        fn values_and_gradients(&self, points: &[DVec3], v: &mut [f64], g: &mut [DVec3]) {
            self.counter.add_gradients(points.len());
            for ((p, v), g) in points.iter().zip(v).zip(g) {
                *v = self.k * sphere(*p);
                *g = self.k * p.normalize_or_zero();
            }
        }
        fn evaluations(&self) -> SdfEvaluations {
            self.counter.get()
        }
    }

    /// A field of values alone ([`Sdf::has_gradient`] false), as a Python callable without
    /// a gradient is: asking it for a gradient is a bug.
    struct ValuesOnly<F>(FnSdf<F>);

    impl<F: Fn(DVec3) -> f64 + Send + Sync> Sdf for ValuesOnly<F> {
        fn values(&self, points: &[DVec3], values: &mut [f64]) {
            self.0.values(points, values);
        }
        fn values_and_gradients(&self, _: &[DVec3], _: &mut [f64], _: &mut [DVec3]) {
            unreachable!("the sampler asked a field without a gradient for one");
        }
        fn evaluations(&self) -> SdfEvaluations {
            self.0.evaluations()
        }
        fn has_gradient(&self) -> bool {
            false
        }
    }

    fn options(resolution: usize, coarse: usize) -> SampleOptions {
        SampleOptions {
            resolution,
            coarse_resolution: coarse,
            band: 1.0,
        }
    }

    /// Deterministic points of `[-r, r]³`.
    fn points(n: usize, r: f64) -> Vec<DVec3> {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 * r - r
        };
        (0..n).map(|_| DVec3::new(next(), next(), next())).collect()
    }

    #[test]
    fn a_quadratic_field_is_reproduced_exactly() {
        let q = |p: DVec3| 0.3 * p.x * p.x - 0.2 * p.y * p.z + 0.5 * p.z * p.z + p.x - 0.1;
        let field = FnSdf::new(q);
        let (sampled, _) = SampledSdf::build(&field, cube(1.0), &options(32, 4)).unwrap();
        for p in points(500, 1.0) {
            let (f, g) = sampled.eval(p);
            assert!((f - q(p)).abs() < 1e-8, "{p}: {f} against {}", q(p));
            let exact = DVec3::new(0.6 * p.x + 1.0, -0.2 * p.z, -0.2 * p.y + p.z);
            assert!((g - exact).length() < 1e-6, "{p}: {g} against {exact}");
        }
    }

    #[test]
    fn interpolated_gradients_match_finite_differences() {
        let field = Sphere::new(1.0);
        let (sampled, _) = SampledSdf::build(&field, cube(1.0), &options(64, 8)).unwrap();
        let h = 1e-6;
        let mut checked = 0;
        for p in points(2000, 1.0) {
            let (_, g) = sampled.eval(p);
            let d = |e: DVec3| (sampled.eval(p + h * e).0 - sampled.eval(p - h * e).0) / (2.0 * h);
            let fd = DVec3::new(d(DVec3::X), d(DVec3::Y), d(DVec3::Z));
            // A difference across a cell's face sees the next cell's interpolant; skip those.
            if (fd - g).length() < 1e-4 * g.length().max(1.0) {
                checked += 1;
            }
        }
        assert!(checked > 1950, "{checked} of 2000 agree");
    }

    #[test]
    fn sampled_values_are_close_to_the_field_near_the_zero_set() {
        let field = Sphere::new(1.0);
        let (sampled, stats) = SampledSdf::build(&field, cube(1.0), &options(128, 16)).unwrap();
        assert_eq!(
            stats.field_evaluations as u64,
            field.evaluations().gradients
        );
        assert_eq!(field.evaluations().values, 0);
        let cell = 2.0 / 128.0;
        for p in points(3000, 1.0) {
            let p = p.normalize_or_zero() * (0.6 + 0.01 * p.x);
            let error = (sampled.eval(p).0 - sphere(p)).abs();
            assert!(error < 1e-2 * cell, "{p}: error {error}");
        }
        for p in points(500, 1.5) {
            assert_eq!(sampled.value(p), sampled.eval(p).0, "{p}");
        }
        // The sampled field counts its own queries, and the field sees none of them.
        let before = field.evaluations();
        let mut v = vec![0.0; 10];
        sampled.values(&points(10, 1.0), &mut v);
        assert_eq!(field.evaluations(), before);
        assert_eq!(sampled.evaluations().values, 10);
    }

    #[test]
    fn refinement_finds_a_plate_thinner_than_the_coarse_cell() {
        // A plate |z − 0.013| < 0.01 : 0.02 thick, a coarse cell is 0.25; with the field's
        // gradients and with differences of the samples.
        let plate = |p: DVec3| (p.z - 0.013).abs() - 0.01;
        let with_gradient = FnSdf::new(plate);
        let values_only = ValuesOnly(FnSdf::new(plate));
        for field in [&with_gradient as &dyn Sdf, &values_only] {
            let (sampled, stats) = SampledSdf::build(field, cube(1.0), &options(128, 8)).unwrap();
            assert!(stats.finest_leaves > 0);
            // Inside the plate the sampled field is negative, above and below positive.
            for p in points(200, 0.9) {
                let inside = DVec3::new(p.x, p.y, 0.013);
                assert!(sampled.eval(inside).0 < 0.0, "{inside}");
                let above = DVec3::new(p.x, p.y, 0.05);
                assert!(sampled.eval(above).0 > 0.0, "{above}");
            }
        }
    }

    #[test]
    fn without_the_fields_gradient_the_samples_are_differenced() {
        let field = ValuesOnly(FnSdf::new(sphere));
        let (sampled, stats) = SampledSdf::build(&field, cube(1.0), &options(128, 16)).unwrap();
        assert!(!stats.field_gradients);
        let counted = field.evaluations();
        assert_eq!(
            (counted.values, counted.gradients),
            (stats.field_evaluations as u64, 0)
        );
        // As many points as with the field's gradient: the differences cost no evaluation.
        let (_, with_gradient) =
            SampledSdf::build(&Sphere::new(1.0), cube(1.0), &options(128, 16)).unwrap();
        let ratio = stats.field_evaluations as f64 / with_gradient.field_evaluations as f64;
        assert!((0.8..1.25).contains(&ratio), "{ratio}");
        let cell = 2.0 / 128.0;
        for p in points(3000, 1.0) {
            let p = p.normalize_or_zero() * (0.6 + 0.01 * p.x);
            let (f, g) = sampled.eval(p);
            assert!(
                (f - sphere(p)).abs() < 0.05 * cell,
                "{p}: error {}",
                f - sphere(p)
            );
            let normal = p.normalize();
            assert!(
                (g - normal).length() < 0.02,
                "{p}: gradient {g} against {normal}"
            );
        }
    }

    #[test]
    fn a_scaled_field_samples_as_well_as_the_unscaled() {
        let unit = Sphere::new(1.0);
        let scaled = Sphere::new(4000.0);
        let (a, sa) = SampledSdf::build(&unit, cube(1.0), &options(64, 8)).unwrap();
        let (b, sb) = SampledSdf::build(&scaled, cube(1.0), &options(64, 8)).unwrap();
        assert_eq!(sa.field_evaluations, sb.field_evaluations);
        assert_eq!(sa.finest_leaves, sb.finest_leaves);
        for p in points(500, 1.5) {
            let (fa, ga) = a.eval(p);
            let (fb, gb) = b.eval(p);
            assert!((fb / 4000.0 - fa).abs() < 1e-9 * fa.abs().max(1.0), "{p}");
            assert!(
                (gb / 4000.0 - ga).length() < 1e-9 * ga.length().max(1.0),
                "{p}"
            );
        }
    }

    #[test]
    fn outside_the_cube_the_field_grows_with_the_median_slope() {
        let scaled = Sphere::new(4000.0);
        let (sampled, stats) = SampledSdf::build(&scaled, cube(1.0), &options(32, 8)).unwrap();
        assert!((stats.median_gradient - 4000.0).abs() < 1e-6);
        let (at_face, _) = sampled.eval(DVec3::new(1.0, 0.0, 0.0));
        let (f, g) = sampled.eval(DVec3::new(1.5, 0.0, 0.0));
        assert!((f - (at_face + 0.5 * 4000.0)).abs() < 1e-6);
        assert!((g.x - 4000.0).abs() < 1e-6);
    }

    #[test]
    fn a_resolution_that_is_not_coarse_times_a_power_of_two_is_refused() {
        let field = Sphere::new(1.0);
        for (resolution, coarse) in [(100, 16), (48, 16), (0, 16), (16, 0)] {
            let error = SampledSdf::build(&field, cube(1.0), &options(resolution, coarse));
            assert!(
                matches!(error, Err(SdfError::Sampling(_))),
                "{resolution}/{coarse}"
            );
        }
        assert_eq!(field.evaluations(), SdfEvaluations::default());
        let opts = SampleOptions::for_resolution(384, 1.0);
        assert_eq!((opts.resolution, opts.coarse_resolution), (384, 24));
        assert_eq!(
            SampleOptions::for_resolution(256, 1.0).coarse_resolution,
            16
        );
    }

    #[test]
    fn a_field_giving_nan_is_a_sampling_error() {
        let field = FnSdf::new(|p: DVec3| if p.x > 0.5 { f64::NAN } else { sphere(p) });
        let error = SampledSdf::build(&field, cube(1.0), &options(32, 8));
        match error {
            Err(SdfError::Sampling(message)) => assert!(message.contains("not finite")),
            _ => panic!("expected a sampling error"),
        }
    }
}
