//! The marching baseline: a field sampled on a regular grid over its bounds and its zero set
//! extracted by marching tetrahedra (`roar_mesh::spatial::isosurface`), a closed, oriented
//! 2-manifold to decimate to a budget and compare against a reconstruction.

use std::time::Instant;

use glam::DVec3;
use roar_mesh::spatial::{Aabb, Sdf, marching_tetrahedra};
use serde::Serialize;

/// How to sample the field.
#[derive(Clone, Debug)]
pub struct ExtractOptions {
    /// Samples along the longest side of the bounds (the others in proportion, at least 2).
    pub resolution: usize,
}

/// What an extraction cost and gave.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ExtractStats {
    /// Samples per axis.
    pub dims: [usize; 3],
    /// Points evaluated for values (one per sample; no gradients).
    pub values: u64,
    /// Seconds evaluating the field.
    pub seconds_sampling: f64,
    /// Seconds of the marching.
    pub seconds_marching: f64,
}

/// The zero set of `sdf` inside `bounds` by marching tetrahedra on a grid of
/// `options.resolution` samples along the longest side: positions and triangles (closed,
/// counter-clockwise from outside) and the cost. The field is evaluated one x-slab at a time, so
/// only the grid of f32 values and one slab of points are held.
pub fn extract_zero_set(
    sdf: &dyn Sdf,
    bounds: &Aabb,
    options: &ExtractOptions,
) -> (Vec<DVec3>, Vec<[u32; 3]>, ExtractStats) {
    let extent = bounds.max - bounds.min;
    let longest = extent.max_element();
    let dims: [usize; 3] = std::array::from_fn(|axis| {
        let n = (extent[axis] / longest * (options.resolution.max(2) - 1) as f64).round();
        (n as usize + 1).max(2)
    });
    let [nx, ny, nz] = dims;
    let step = extent / DVec3::new((nx - 1) as f64, (ny - 1) as f64, (nz - 1) as f64);
    let started = Instant::now();
    let mut values = vec![0.0f32; nx * ny * nz];
    let mut points = Vec::with_capacity(ny * nz);
    let mut slab = vec![0.0f64; ny * nz];
    for (i, out) in values.chunks_mut(ny * nz).enumerate() {
        points.clear();
        for j in 0..ny {
            for k in 0..nz {
                points.push(bounds.min + DVec3::new(i as f64, j as f64, k as f64) * step);
            }
        }
        sdf.values(&points, &mut slab);
        for (o, v) in out.iter_mut().zip(&slab) {
            *o = *v as f32;
        }
    }
    let seconds_sampling = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let (positions, triangles) = marching_tetrahedra(&values, dims, bounds.min, bounds.max);
    let stats = ExtractStats {
        dims,
        values: values.len() as u64,
        seconds_sampling,
        seconds_marching: started.elapsed().as_secs_f64(),
    };
    (positions, triangles, stats)
}
