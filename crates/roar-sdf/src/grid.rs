//! A dense grid SDF: signed distances sampled on a regular grid, read from an `.npy` volume
//! (float32 or float64, C or Fortran order) and interpolated trilinearly.
//!
//! The volume has shape `(nx, ny, nz)`, each at least 2; its element `[i][j][k]` is the value at
//! `min + (i/(nx−1), j/(ny−1), k/(nz−1)) ⊙ (max − min)`, so the first and last samples of each
//! axis lie on the bounds (the placement `np.linspace(min, max, n)` gives). Negative inside.
//! The bounds come from a JSON sidecar beside the volume, the same name with `.json` in place of
//! `.npy` (`{"min": [x, y, z], "max": [x, y, z]}`); without one the caller places the grid.
//!
//! Outside the bounds the field is the value at the nearest point of the box plus the distance to
//! it, so tracers and projectors that step out of the grid see a field that grows away from it.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::DVec3;
use ndarray::ArrayD;
use ndarray_npy::{ReadNpyError, ReadNpyExt};
use rayon::prelude::*;
use roar_mesh::spatial::{Aabb, Sdf, SdfCounter, SdfEvaluations};
use serde::Deserialize;

use crate::error::SdfError;

/// Points interpolated per parallel task.
const CHUNK: usize = 4096;

/// Bounds as a sidecar writes them: `{"min": [x, y, z], "max": [x, y, z]}` (a grid's whole
/// sidecar; the `bounds` of a network's).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct BoundsSpec {
    min: [f64; 3],
    max: [f64; 3],
}

impl BoundsSpec {
    /// The box, or why it is none.
    pub(crate) fn to_aabb(&self) -> Result<Aabb, SdfError> {
        let bounds = Aabb {
            min: DVec3::from_array(self.min),
            max: DVec3::from_array(self.max),
        };
        check_bounds(&bounds)?;
        Ok(bounds)
    }
}

/// Samples of a signed distance on a regular grid over `bounds` ([module docs](self)).
#[derive(Debug)]
pub struct GridSdf {
    /// `[nx, ny, nz]`.
    dims: [usize; 3],
    /// Values in C order: index `(i·ny + j)·nz + k`.
    values: Vec<f64>,
    bounds: Aabb,
    counter: SdfCounter,
}

impl GridSdf {
    /// A grid of `values` (C order, `dims[0]·dims[1]·dims[2]` of them) placed over `bounds`.
    /// Fails in one line when a dimension is below 2, the count does not match, a value is not
    /// finite, or the bounds are not a box of positive extent.
    pub fn new(dims: [usize; 3], values: Vec<f64>, bounds: Aabb) -> Result<Self, SdfError> {
        let bad = |m: String| SdfError::Grid(m);
        if dims.iter().any(|&n| n < 2) {
            return Err(bad(format!(
                "the grid is {} × {} × {}; every axis needs at least 2 samples",
                dims[0], dims[1], dims[2]
            )));
        }
        if values.len() != dims[0] * dims[1] * dims[2] {
            return Err(bad(format!(
                "{} values for a {} × {} × {} grid",
                values.len(),
                dims[0],
                dims[1],
                dims[2]
            )));
        }
        if let Some(at) = values.iter().position(|v| !v.is_finite()) {
            let (i, j, k) = (
                at / (dims[1] * dims[2]),
                (at / dims[2]) % dims[1],
                at % dims[2],
            );
            return Err(bad(format!(
                "the grid holds {} at [{i}, {j}, {k}]",
                values[at]
            )));
        }
        check_bounds(&bounds)?;
        Ok(Self {
            dims,
            values,
            bounds,
            counter: SdfCounter::default(),
        })
    }

    /// Reads an `.npy` volume (float32 or float64, 3 axes, C or Fortran order) placed over
    /// `bounds` (the sidecar's, [`read_sidecar`]). Every malformed file gives a one-line
    /// [`SdfError::Grid`].
    pub fn from_npy_file(path: &Path, bounds: Aabb) -> Result<Self, SdfError> {
        let bytes = std::fs::read(path).map_err(|e| SdfError::Io(e.to_string()))?;
        Self::from_npy_bytes(&bytes, bounds)
    }

    /// Reads an `.npy` volume from its bytes, placed over `bounds` ([`GridSdf::from_npy_file`]).
    pub fn from_npy_bytes(bytes: &[u8], bounds: Aabb) -> Result<Self, SdfError> {
        let array = read_volume(bytes)?;
        let shape = array.shape().to_vec();
        if shape.len() != 3 {
            return Err(SdfError::Grid(format!(
                "the volume has {} axes {shape:?}; a grid SDF needs 3",
                shape.len()
            )));
        }
        // Logical [i][j][k] order whatever the file's memory order.
        let values: Vec<f64> = array.iter().copied().collect();
        Self::new([shape[0], shape[1], shape[2]], values, bounds)
    }

    /// The box the samples span.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Samples along x, y and z.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    fn at(&self, i: usize, j: usize, k: usize) -> f64 {
        self.values[(i * self.dims[1] + j) * self.dims[2] + k]
    }

    /// Value and gradient at `p`: trilinear inside the box, and outside it the value at the
    /// nearest box point plus the distance to that point.
    fn eval(&self, p: DVec3) -> (f64, DVec3) {
        let q = p.clamp(self.bounds.min, self.bounds.max);
        let extent = self.bounds.max - self.bounds.min;
        let mut cell = [0usize; 3];
        let mut t = [0.0f64; 3];
        let mut scale = [0.0f64; 3];
        for axis in 0..3 {
            let cells = (self.dims[axis] - 1) as f64;
            let u = (q[axis] - self.bounds.min[axis]) / extent[axis] * cells;
            let c = (u.floor().max(0.0) as usize).min(self.dims[axis] - 2);
            cell[axis] = c;
            t[axis] = u - c as f64;
            scale[axis] = cells / extent[axis];
        }
        let [i, j, k] = cell;
        let [tx, ty, tz] = t;
        // Corner values c[dx][dy][dz].
        let c = |dx, dy, dz| self.at(i + dx, j + dy, k + dz);
        let lerp = |a: f64, b: f64, s: f64| a + (b - a) * s;
        let c00 = lerp(c(0, 0, 0), c(1, 0, 0), tx);
        let c01 = lerp(c(0, 0, 1), c(1, 0, 1), tx);
        let c10 = lerp(c(0, 1, 0), c(1, 1, 0), tx);
        let c11 = lerp(c(0, 1, 1), c(1, 1, 1), tx);
        let c0 = lerp(c00, c10, ty);
        let c1 = lerp(c01, c11, ty);
        let value = lerp(c0, c1, tz);
        // Partial derivatives of the trilinear form in cell units, then per unit length.
        let dx = {
            let d00 = c(1, 0, 0) - c(0, 0, 0);
            let d01 = c(1, 0, 1) - c(0, 0, 1);
            let d10 = c(1, 1, 0) - c(0, 1, 0);
            let d11 = c(1, 1, 1) - c(0, 1, 1);
            lerp(lerp(d00, d10, ty), lerp(d01, d11, ty), tz)
        };
        let dy = lerp(c10 - c00, c11 - c01, tz);
        let dz = c1 - c0;
        let mut gradient = DVec3::new(dx * scale[0], dy * scale[1], dz * scale[2]);
        let outside = p - q;
        let distance = outside.length();
        if distance > 0.0 {
            let away = outside / distance;
            for axis in 0..3 {
                if outside[axis] != 0.0 {
                    gradient[axis] = away[axis];
                }
            }
        }
        (value + distance, gradient)
    }
}

impl Sdf for GridSdf {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        self.counter.add_values(points.len());
        points
            .par_chunks(CHUNK)
            .zip(values.par_chunks_mut(CHUNK))
            .for_each(|(p, v)| {
                for (p, v) in p.iter().zip(v) {
                    *v = self.eval(*p).0;
                }
            });
    }

    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        self.counter.add_gradients(points.len());
        points
            .par_chunks(CHUNK)
            .zip(values.par_chunks_mut(CHUNK))
            .zip(gradients.par_chunks_mut(CHUNK))
            .for_each(|((p, v), g)| {
                for ((p, v), g) in p.iter().zip(v).zip(g) {
                    (*v, *g) = self.eval(*p);
                }
            });
    }

    fn evaluations(&self) -> SdfEvaluations {
        self.counter.get()
    }
}

/// The sidecar of the volume at `path`: the same name with `.json` in place of `.npy`.
pub fn sidecar_path(path: &Path) -> PathBuf {
    path.with_extension("json")
}

/// The bounds in the sidecar of `path`, or `None` when there is no sidecar.
pub fn read_sidecar(path: &Path) -> Result<Option<Aabb>, SdfError> {
    let sidecar = sidecar_path(path);
    let text = match std::fs::read_to_string(&sidecar) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(SdfError::Io(format!("{}: {e}", sidecar.display()))),
    };
    let spec: BoundsSpec = serde_json::from_str(&text).map_err(|e| {
        SdfError::Grid(format!(
            "{}: {e} (expected {{\"min\": [x, y, z], \"max\": [x, y, z]}})",
            sidecar.display()
        ))
    })?;
    let bounds = spec
        .to_aabb()
        .map_err(|e| SdfError::Grid(format!("{}: {e}", sidecar.display())))?;
    Ok(Some(bounds))
}

fn check_bounds(bounds: &Aabb) -> Result<(), SdfError> {
    if !bounds.min.is_finite() || !bounds.max.is_finite() || !bounds.min.cmplt(bounds.max).all() {
        return Err(SdfError::Grid(format!(
            "bounds min {} max {} are not a box (each max must be above its min)",
            bounds.min, bounds.max
        )));
    }
    Ok(())
}

/// The volume as f64, read as float64 or else as float32.
fn read_volume(bytes: &[u8]) -> Result<ArrayD<f64>, SdfError> {
    let bad = |e: ReadNpyError| SdfError::Grid(format!("not a float32/float64 .npy volume: {e}"));
    match ArrayD::<f64>::read_npy(Cursor::new(bytes)) {
        Ok(array) => Ok(array),
        Err(ReadNpyError::WrongDescriptor(_)) => ArrayD::<f32>::read_npy(Cursor::new(bytes))
            .map(|a| a.mapv(f64::from))
            .map_err(bad),
        Err(e) => Err(bad(e)),
    }
}
