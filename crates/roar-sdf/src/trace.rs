//! Normal maps of an SDF's zero set, one per camera, as `roar_loss::render_views` makes them for
//! a mesh (RGB the outward unit normal, alpha 1 where the surface is seen, background 0).
//!
//! The tracer is grid-bracketed rather than a plain sphere tracer, to spend few SDF evaluations:
//! 1. the SDF's values on a coarse grid of corners over the bounds (one batch, no gradients);
//! 2. each pixel's ray, clipped to the bounds, marches the grid's trilinear interpolant until it
//!    turns negative, which brackets the first crossing: in steps of half a cell, or of
//!    `|value|/L` where that is longer, `L` a bound on the interpolant's slope (no crossing of
//!    the interpolant lies closer), so empty space is crossed in a few steps;
//! 3. the bracket is confirmed with the SDF itself (its value at both ends must change sign;
//!    when both ends are outside, a few values inside it may find a thin part; when both are
//!    inside, it moves back a few steps along the ray) and shrunk by
//!    Illinois regula falsi on the SDF's values, all rays of a view in one batch per step;
//! 4. one value-and-gradient evaluation at the root gives the normal `∇f/|∇f|`.
//!
//! Crossings that the grid's interpolant does not see (features thinner than about a cell) and
//! brackets the SDF does not confirm are left as background; [`TraceStats`] counts them.

use std::time::Instant;

use glam::{DMat4, DVec3, DVec4};
use rayon::prelude::*;
use roar_mesh::spatial::{Aabb, Sdf};
use roar_render::{Camera, Image};

/// Field values looked at inside a bracket whose ends are both outside.
const THIN_SAMPLES: usize = 7;

/// Steps of half a cell a bracket may move back toward the ray's entry.
const BACK_STEPS: usize = 4;

/// Options of [`trace_normal_maps`].
#[derive(Clone, Debug, PartialEq)]
pub struct TraceOptions {
    /// Cells of the bracketing grid along the longest side of the bounds.
    pub grid_resolution: usize,
    /// Regula falsi steps on each confirmed bracket.
    pub refine_steps: usize,
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self {
            grid_resolution: 128,
            refine_steps: 8,
        }
    }
}

/// What [`trace_normal_maps`] did, for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceStats {
    /// Rays cast (pixels of all views).
    pub rays: usize,
    /// Rays that hit the surface.
    pub hits: usize,
    /// Brackets of the grid's interpolant that the SDF did not confirm (left as background).
    pub unconfirmed: usize,
    /// Points evaluated for values (grid and refinement) and for gradients (normals).
    pub value_evaluations: usize,
    /// See `value_evaluations`.
    pub gradient_evaluations: usize,
    /// Wall time.
    pub seconds: f64,
}

/// SDF values on the corners of a regular grid over a box.
struct CornerGrid {
    origin: DVec3,
    cell: f64,
    /// Corners per axis.
    dims: [usize; 3],
    values: Vec<f64>,
    /// A bound on the slope of the trilinear interpolant: `√3` times the largest difference
    /// between neighbouring corners over the cell (finite values only); `∞` when there is none.
    slope: f64,
}

impl CornerGrid {
    fn new(sdf: &dyn Sdf, bounds: &Aabb, resolution: usize) -> Self {
        let cell = bounds.extent().max_element() / resolution.max(1) as f64;
        let dims = [0, 1, 2].map(|a| ((bounds.extent()[a] / cell).ceil() as usize).max(1) + 1);
        let mut points = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    points.push(bounds.min + cell * DVec3::new(i as f64, j as f64, k as f64));
                }
            }
        }
        let mut values = vec![0.0; points.len()];
        sdf.values(&points, &mut values);
        // A NaN counts as outside, so it never brackets a crossing.
        for v in &mut values {
            if v.is_nan() {
                *v = f64::INFINITY;
            }
        }
        // Along each axis, the interpolant's derivative is a blend of the cell's corner
        // differences over the cell, so its gradient is at most √3 times the largest of them.
        let strides = [1, dims[0], dims[0] * dims[1]];
        let mut largest: f64 = 0.0;
        for (idx, &here) in values.iter().enumerate() {
            let at = [idx % dims[0], (idx / dims[0]) % dims[1], idx / strides[2]];
            for axis in 0..3 {
                if at[axis] + 1 < dims[axis] {
                    let d = (values[idx + strides[axis]] - here).abs();
                    if d.is_finite() {
                        largest = largest.max(d);
                    }
                }
            }
        }
        let slope = if largest > 0.0 {
            3f64.sqrt() * largest / cell
        } else {
            f64::INFINITY
        };
        Self {
            origin: bounds.min,
            cell,
            dims,
            values,
            slope,
        }
    }

    /// How far a ray may step from a point where the interpolant is `value` without passing a
    /// crossing: `|value|/slope`, at least `least`.
    fn safe_step(&self, value: f64, least: f64) -> f64 {
        let step = value.abs() / self.slope;
        if step.is_finite() {
            step.max(least)
        } else {
            least
        }
    }

    /// The trilinear interpolant at `p` (clamped to the grid).
    fn at(&self, p: DVec3) -> f64 {
        let q = (p - self.origin) / self.cell;
        let mut base = [0usize; 3];
        let mut frac = [0.0; 3];
        for a in 0..3 {
            let max = (self.dims[a] - 2) as f64;
            let x = q[a].clamp(0.0, max + 1.0);
            let i = x.floor().min(max);
            base[a] = i as usize;
            frac[a] = x - i;
        }
        let index = |i: usize, j: usize, k: usize| {
            self.values
                [(base[0] + i) + self.dims[0] * ((base[1] + j) + self.dims[1] * (base[2] + k))]
        };
        let mut value = 0.0;
        for (k, wk) in [(0, 1.0 - frac[2]), (1, frac[2])] {
            for (j, wj) in [(0, 1.0 - frac[1]), (1, frac[1])] {
                for (i, wi) in [(0, 1.0 - frac[0]), (1, frac[0])] {
                    value += wi * wj * wk * index(i, j, k);
                }
            }
        }
        value
    }
}

/// The ray through the centre of pixel `(x, y)` of `camera`: origin on the near plane, unit
/// direction.
fn pixel_ray(inverse: &DMat4, camera: &Camera, x: u32, y: u32) -> (DVec3, DVec3) {
    let ndc_x = 2.0 * (x as f64 + 0.5) / camera.width as f64 - 1.0;
    let ndc_y = 2.0 * (y as f64 + 0.5) / camera.height as f64 - 1.0;
    let unproject = |z: f64| {
        let h = *inverse * DVec4::new(ndc_x, ndc_y, z, 1.0);
        h.truncate() / h.w
    };
    let near = unproject(-1.0);
    let far = unproject(1.0);
    (near, (far - near).normalize())
}

/// A bracketed crossing of one pixel's ray: `f(origin + a·dir) ≥ 0 > f(origin + b·dir)`.
struct Bracket {
    pixel: usize,
    origin: DVec3,
    dir: DVec3,
    t_in: f64,
    a: f64,
    b: f64,
    fa: f64,
    fb: f64,
}

/// One normal map per camera of the zero set of `sdf` inside `bounds` ([module docs](self)).
pub fn trace_normal_maps(
    sdf: &dyn Sdf,
    bounds: &Aabb,
    cameras: &[Camera],
    options: &TraceOptions,
) -> (Vec<Image>, TraceStats) {
    let start = Instant::now();
    let before = sdf.evaluations();
    let grid = CornerGrid::new(sdf, bounds, options.grid_resolution);
    let step = 0.5 * grid.cell;
    let mut stats = TraceStats::default();
    let mut images = Vec::with_capacity(cameras.len());
    for camera in cameras {
        let inverse = camera.view_proj().inverse();
        let width = camera.width;
        let pixels = camera.num_pixels();
        stats.rays += pixels;
        // 2. March the interpolant.
        let mut brackets: Vec<Bracket> = (0..pixels)
            .into_par_iter()
            .filter_map(|pixel| {
                let (x, y) = (pixel as u32 % width, pixel as u32 / width);
                let (origin, dir) = pixel_ray(&inverse, camera, x, y);
                let (t_in, t_out) = bounds.ray_interval(origin, dir)?;
                let mut t = t_in;
                let mut previous = grid.at(origin + t * dir);
                while t < t_out {
                    let next = (t + grid.safe_step(previous, step)).min(t_out);
                    let value = grid.at(origin + next * dir);
                    if previous >= 0.0 && value < 0.0 {
                        return Some(Bracket {
                            pixel,
                            origin,
                            dir,
                            t_in,
                            a: t,
                            b: next,
                            fa: 0.0,
                            fb: 0.0,
                        });
                    }
                    previous = value;
                    t = next;
                }
                None
            })
            .collect();
        // 3. Confirm with the SDF.
        let ends: Vec<DVec3> = brackets
            .iter()
            .flat_map(|r| [r.origin + r.a * r.dir, r.origin + r.b * r.dir])
            .collect();
        let mut values = vec![0.0; ends.len()];
        sdf.values(&ends, &mut values);
        for (r, f) in brackets.iter_mut().zip(values.chunks(2)) {
            (r.fa, r.fb) = (f[0], f[1]);
        }
        // A bracket whose ends are both outside may hold a part thinner than the step: look
        // for the field's first negative value at a few points inside it.
        let thin: Vec<usize> = (0..brackets.len())
            .filter(|&i| brackets[i].fa >= 0.0 && brackets[i].fb >= 0.0)
            .collect();
        let inner: Vec<DVec3> = thin
            .iter()
            .flat_map(|&i| {
                let r = &brackets[i];
                (1..=THIN_SAMPLES).map(move |k| {
                    let t = r.a + (r.b - r.a) * k as f64 / (THIN_SAMPLES + 1) as f64;
                    r.origin + t * r.dir
                })
            })
            .collect();
        let mut values = vec![0.0; inner.len()];
        sdf.values(&inner, &mut values);
        for (&i, samples) in thin.iter().zip(values.chunks(THIN_SAMPLES)) {
            let r = &mut brackets[i];
            if let Some(k) = samples.iter().position(|&f| f < 0.0) {
                let t = |k: usize| r.a + (r.b - r.a) * k as f64 / (THIN_SAMPLES + 1) as f64;
                let (a, b) = (t(k), t(k + 1));
                r.fa = if k == 0 { r.fa } else { samples[k - 1] };
                (r.a, r.b, r.fb) = (a, b, samples[k]);
            }
        }
        // A bracket whose start is already inside: the field crossed earlier than the grid's
        // interpolant; step back toward the ray's entry until the field is outside.
        for _ in 0..BACK_STEPS {
            let back: Vec<usize> = (0..brackets.len())
                .filter(|&i| brackets[i].fa < 0.0 && brackets[i].a > brackets[i].t_in)
                .collect();
            if back.is_empty() {
                break;
            }
            let points: Vec<DVec3> = back
                .iter()
                .map(|&i| {
                    let r = &brackets[i];
                    r.origin + (r.a - step).max(r.t_in) * r.dir
                })
                .collect();
            let mut values = vec![0.0; points.len()];
            sdf.values(&points, &mut values);
            for (&i, &f) in back.iter().zip(&values) {
                let r = &mut brackets[i];
                (r.b, r.fb) = (r.a, r.fa);
                (r.a, r.fa) = ((r.a - step).max(r.t_in), f);
            }
        }
        let confirmed = brackets.len();
        brackets.retain(|r| r.fa >= 0.0 && r.fb < 0.0);
        stats.unconfirmed += confirmed - brackets.len();
        // Illinois regula falsi, one batch per step.
        let mut side = vec![0i8; brackets.len()];
        for _ in 0..options.refine_steps {
            let points: Vec<DVec3> = brackets
                .iter()
                .map(|r| r.origin + falsi(r) * r.dir)
                .collect();
            let mut values = vec![0.0; points.len()];
            sdf.values(&points, &mut values);
            for ((r, &f), last) in brackets.iter_mut().zip(&values).zip(&mut side) {
                let t = falsi(r);
                if f >= 0.0 {
                    (r.a, r.fa) = (t, f);
                    if *last == 1 {
                        r.fb *= 0.5;
                    }
                    *last = 1;
                } else if f < 0.0 {
                    (r.b, r.fb) = (t, f);
                    if *last == -1 {
                        r.fa *= 0.5;
                    }
                    *last = -1;
                }
            }
        }
        // 4. Normals at the roots.
        let roots: Vec<DVec3> = brackets
            .iter()
            .map(|r| r.origin + falsi(r) * r.dir)
            .collect();
        let mut values = vec![0.0; roots.len()];
        let mut gradients = vec![DVec3::ZERO; roots.len()];
        sdf.values_and_gradients(&roots, &mut values, &mut gradients);
        let mut image: Image = vec![[0.0; 4]; pixels];
        for (r, g) in brackets.iter().zip(&gradients) {
            let n = g.normalize_or_zero();
            if n != DVec3::ZERO {
                image[r.pixel] = [n.x as f32, n.y as f32, n.z as f32, 1.0];
                stats.hits += 1;
            }
        }
        images.push(image);
    }
    let counted = sdf.evaluations() - before;
    stats.value_evaluations = counted.values as usize;
    stats.gradient_evaluations = counted.gradients as usize;
    stats.seconds = start.elapsed().as_secs_f64();
    (images, stats)
}

/// The regula falsi point of a bracket (its midpoint when the values do not separate it).
fn falsi(r: &Bracket) -> f64 {
    let denominator = r.fa - r.fb;
    if denominator > 0.0 && denominator.is_finite() {
        r.a + (r.b - r.a) * r.fa / denominator
    } else {
        0.5 * (r.a + r.b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::spatial::FnSdf;
    use roar_render::star_cameras;

    #[test]
    fn long_steps_through_empty_space_miss_no_small_sphere() {
        // Two spheres a few cells wide in a large box: most of every ray is empty space, where
        // the steps are longest. Every pixel whose ray meets a sphere must see it.
        let centres = [DVec3::new(0.5, 0.3, -0.2), DVec3::new(-0.6, -0.4, 0.3)];
        let radius = 0.15;
        let field = FnSdf::new(move |p: DVec3| {
            centres
                .iter()
                .map(|c| p.distance(*c) - radius)
                .fold(f64::INFINITY, f64::min)
        });
        let bounds = Aabb {
            min: DVec3::splat(-1.0),
            max: DVec3::splat(1.0),
        };
        let options = TraceOptions {
            grid_resolution: 32,
            ..TraceOptions::default()
        };
        let cameras = star_cameras(3, 2, 96, 96);
        let (images, _) = trace_normal_maps(&field, &bounds, &cameras, &options);
        let (mut expected, mut missed) = (0, 0);
        for (camera, image) in cameras.iter().zip(&images) {
            let inverse = camera.view_proj().inverse();
            for (pixel, rgba) in image.iter().enumerate() {
                let (x, y) = (pixel as u32 % camera.width, pixel as u32 / camera.width);
                let (origin, dir) = pixel_ray(&inverse, camera, x, y);
                // Clear of the silhouette by a tenth of the radius: grazing rays may go either way.
                let meets = centres.iter().any(|c| {
                    let to = *c - origin;
                    let along = to.dot(dir);
                    along > 0.0 && (to - along * dir).length() < 0.9 * radius
                });
                if meets {
                    expected += 1;
                    missed += usize::from(rgba[3] == 0.0);
                }
            }
        }
        assert!(expected > 500, "{expected} pixels see a sphere");
        assert_eq!(missed, 0, "{missed} of {expected} missed");
    }
}
