//! A neural SDF: an MLP evaluated in f32 batches with its input gradient by backpropagation,
//! read from a sequential `.npz` file (the format of the neural-implicit-queries sample networks,
//! below) or from an IDR/VolSDF/NeuS state dict in `.safetensors` ([`crate::implicit_network`]).
//!
//! The file is a zip of `.npy` arrays whose names are `NNNN.KIND…`, applied in the order of
//! their 4-digit prefix: `NNNN.dense.A` (in × out) with `NNNN.dense.b` (out), `y = x·A + b`; an
//! activation `NNNN.relu._`, `elu`, `tanh`, `sin` or `softplus` (an empty array; only the name
//! counts); `NNNN.squeeze_last._` (take the single output). The first layer takes 3 inputs and
//! the last gives 1.

use std::collections::BTreeMap;
use std::f32::consts::FRAC_1_SQRT_2;
use std::fs::File;
use std::io::{Read, Seek};
use std::path::Path;

use glam::DVec3;
use ndarray::{Array1, Array2, ArrayD, Axis, Dimension, Ix1, Ix2, Slice, concatenate};
use ndarray_npy::NpzReader;
use rayon::prelude::*;
use roar_mesh::spatial::{Sdf, SdfCounter, SdfEvaluations};

use crate::error::SdfError;

/// Points evaluated together in one matrix product (rows of a batch); batches run in parallel.
const CHUNK: usize = 2048;

/// An elementwise activation of a layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Activation {
    /// `max(z, 0)`.
    Relu,
    /// `z` for `z > 0`, `eᶻ − 1` otherwise.
    Elu,
    /// `tanh z`.
    Tanh,
    /// `sin z`.
    Sin,
    /// `ln(1 + e^{βz}) / β`: β = 1 in `.npz` files, 100 in IDR/VolSDF/NeuS networks.
    Softplus {
        /// The sharpness β.
        beta: f32,
    },
}

impl Activation {
    fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "relu" => Self::Relu,
            "elu" => Self::Elu,
            "tanh" => Self::Tanh,
            "sin" => Self::Sin,
            "softplus" => Self::Softplus { beta: 1.0 },
            _ => return None,
        })
    }

    fn value(self, z: f32) -> f32 {
        match self {
            Self::Relu => z.max(0.0),
            Self::Elu => {
                if z > 0.0 {
                    z
                } else {
                    z.exp_m1()
                }
            }
            Self::Tanh => z.tanh(),
            Self::Sin => z.sin(),
            Self::Softplus { beta } => {
                let bz = beta * z;
                (bz.max(0.0) + (-bz.abs()).exp().ln_1p()) / beta
            }
        }
    }

    fn derivative(self, z: f32) -> f32 {
        match self {
            Self::Relu => f32::from(z > 0.0),
            Self::Elu => {
                if z > 0.0 {
                    1.0
                } else {
                    z.exp()
                }
            }
            Self::Tanh => 1.0 - z.tanh().powi(2),
            Self::Sin => z.cos(),
            Self::Softplus { beta } => 1.0 / (1.0 + (-beta * z).exp()),
        }
    }
}

/// One step of the network.
#[derive(Clone, Debug)]
pub(crate) enum Op {
    /// `y = x·a + b`, `a` in × out.
    Dense { a: Array2<f32>, b: Array1<f32> },
    /// Elementwise activation.
    Activation(Activation),
    /// `y = s·x`.
    Scale(f32),
    /// The positional encoding `(x, sin 2⁰x, cos 2⁰x, …, sin 2ᵏ⁻¹x, cos 2ᵏ⁻¹x)` with `k`
    /// frequencies (IDR's embedder; `k = 0` is the identity). Its output is the encoded input
    /// that [`Op::ConcatEncoded`] appends; a network has at most one, before any of those.
    Encode { frequencies: u32 },
    /// `y = (x, e) / √2` with `e` the encoded input (a skip connection of IDR/NeuS).
    ConcatEncoded,
}

/// A sequential MLP `R³ → R` ([module docs](self): the format).
#[derive(Debug)]
pub struct Mlp {
    ops: Vec<Op>,
    counter: SdfCounter,
}

impl Mlp {
    /// Reads an `.npz` network; every malformed file gives a one-line [`SdfError::Network`]
    /// naming the tensor (missing, wrong shape, non-finite value, unknown layer) or the zip error.
    pub fn from_npz_file(path: &Path) -> Result<Self, SdfError> {
        let file = File::open(path).map_err(|e| SdfError::Io(e.to_string()))?;
        Self::from_npz(file)
    }

    /// Reads an `.npz` network from any reader ([`Mlp::from_npz_file`]).
    pub fn from_npz<R: Read + Seek>(reader: R) -> Result<Self, SdfError> {
        let bad = |m: String| SdfError::Network(m);
        let mut npz = NpzReader::new(reader).map_err(|e| bad(format!("not an npz file: {e}")))?;
        let names = npz
            .names()
            .map_err(|e| bad(format!("unreadable npz: {e}")))?;
        // Keys by prefix, each with its kind: "dense.A", "relu._", …
        let mut entries: BTreeMap<u32, Vec<(String, String)>> = BTreeMap::new();
        for name in names {
            let (prefix, kind) = name
                .split_once('.')
                .and_then(|(p, k)| Some((p.parse::<u32>().ok()?, k.to_string())))
                .ok_or_else(|| bad(format!("{name}: not a NNNN.kind layer key")))?;
            entries.entry(prefix).or_default().push((kind, name));
        }
        let mut ops = Vec::new();
        let mut width = 3usize;
        let mut width_from = "the input (x, y, z)".to_string();
        let mut squeezed = false;
        for (prefix, kinds) in &entries {
            if squeezed {
                return Err(bad(format!(
                    "{prefix:04}: a layer after squeeze_last (it must come last)"
                )));
            }
            let key = |kind: &str| format!("{prefix:04}.{kind}");
            let has = |kind: &str| kinds.iter().any(|(k, _)| k == kind);
            if has("dense.A") || has("dense.b") {
                if !has("dense.A") {
                    return Err(bad(format!("{} is missing", key("dense.A"))));
                }
                if !has("dense.b") {
                    return Err(bad(format!("{} is missing", key("dense.b"))));
                }
                let a: Array2<f32> = read_tensor::<_, Ix2>(&mut npz, &key("dense.A"))?;
                let b: Array1<f32> = read_tensor::<_, Ix1>(&mut npz, &key("dense.b"))?;
                if a.nrows() != width {
                    return Err(bad(format!(
                        "{} is {} × {} but its input has {width} values (from {width_from})",
                        key("dense.A"),
                        a.nrows(),
                        a.ncols()
                    )));
                }
                if b.len() != a.ncols() {
                    return Err(bad(format!(
                        "{} has {} values but {} has {} columns",
                        key("dense.b"),
                        b.len(),
                        key("dense.A"),
                        a.ncols()
                    )));
                }
                width = a.ncols();
                width_from = key("dense.A");
                ops.push(Op::Dense { a, b });
                if kinds.len() > 2 {
                    return Err(bad(format!(
                        "{prefix:04}: more than one layer at one prefix"
                    )));
                }
                continue;
            }
            let [(kind, _)] = kinds.as_slice() else {
                return Err(bad(format!(
                    "{prefix:04}: more than one layer at one prefix"
                )));
            };
            let name = kind.strip_suffix("._").unwrap_or(kind);
            if name == "squeeze_last" {
                if width != 1 {
                    return Err(bad(format!(
                        "{} squeezes {width} outputs (from {width_from}); it needs 1",
                        key(kind)
                    )));
                }
                squeezed = true;
            } else if let Some(activation) = Activation::from_name(name) {
                ops.push(Op::Activation(activation));
            } else {
                return Err(bad(format!(
                    "{}: unknown layer '{name}' (dense, relu, elu, tanh, sin, softplus, \
                     squeeze_last)",
                    key(kind)
                )));
            }
        }
        if !ops.iter().any(|op| matches!(op, Op::Dense { .. })) {
            return Err(bad("no dense layer (NNNN.dense.A / NNNN.dense.b)".into()));
        }
        if width != 1 {
            return Err(bad(format!(
                "the network gives {width} values per point (from {width_from}); an SDF gives 1"
            )));
        }
        Ok(Self {
            ops,
            counter: SdfCounter::default(),
        })
    }

    /// A network of `ops` mapping 3 inputs to 1 output (the caller checked the widths).
    pub(crate) fn from_ops(ops: Vec<Op>) -> Self {
        Self {
            ops,
            counter: SdfCounter::default(),
        }
    }

    /// A network of dense layers `(A, b)` with `activation` between them (none after the last):
    /// for tests and benches.
    pub fn from_layers(layers: Vec<(Array2<f32>, Array1<f32>)>, activation: Activation) -> Self {
        let n = layers.len();
        let mut ops = Vec::new();
        for (i, (a, b)) in layers.into_iter().enumerate() {
            ops.push(Op::Dense { a, b });
            if i + 1 < n {
                ops.push(Op::Activation(activation));
            }
        }
        Self {
            ops,
            counter: SdfCounter::default(),
        }
    }

    /// `f` of a batch of points (rows of `x`, n × 3), and when `with_gradient` its input
    /// gradient (n × 3) by backpropagation.
    fn forward(&self, x: Array2<f32>, with_gradient: bool) -> (Vec<f32>, Option<Array2<f32>>) {
        let mut inputs: Vec<Array2<f32>> = Vec::new();
        let mut encoded: Option<Array2<f32>> = None;
        let mut h = x;
        for op in &self.ops {
            let next = match op {
                Op::Dense { a, b } => h.dot(a) + b,
                Op::Activation(act) => h.mapv(|z| act.value(z)),
                Op::Scale(s) => h.mapv(|z| s * z),
                Op::Encode { frequencies } => {
                    let e = encode(&h, *frequencies);
                    encoded = Some(e.clone());
                    e
                }
                Op::ConcatEncoded => {
                    let e = encoded.as_ref().expect("the encoding comes before a skip");
                    concatenate(Axis(1), &[h.view(), e.view()])
                        .expect("one row per point")
                        .mapv(|z| z * FRAC_1_SQRT_2)
                }
            };
            if with_gradient {
                inputs.push(std::mem::replace(&mut h, next));
            } else {
                h = next;
            }
        }
        let values = h.column(0).to_vec();
        if !with_gradient {
            return (values, None);
        }
        let mut g = Array2::<f32>::ones((values.len(), 1));
        // The gradient reaching the encoded input through the skip connections.
        let mut g_encoded: Option<Array2<f32>> = None;
        for (op, input) in self.ops.iter().zip(&inputs).rev() {
            g = match op {
                Op::Dense { a, .. } => g.dot(&a.t()),
                Op::Activation(act) => {
                    g.zip_mut_with(input, |g, &z| *g *= act.derivative(z));
                    g
                }
                Op::Scale(s) => g.mapv(|z| s * z),
                Op::ConcatEncoded => {
                    let width = input.ncols();
                    let to_e = g
                        .slice_axis(Axis(1), Slice::from(width..))
                        .mapv(|z| z * FRAC_1_SQRT_2);
                    g_encoded = Some(match g_encoded.take() {
                        Some(sum) => sum + to_e,
                        None => to_e,
                    });
                    g.slice_axis(Axis(1), Slice::from(..width))
                        .mapv(|z| z * FRAC_1_SQRT_2)
                }
                Op::Encode { frequencies } => {
                    if let Some(skips) = g_encoded.take() {
                        g += &skips;
                    }
                    encode_backward(input, &g, *frequencies)
                }
            };
        }
        (values, Some(g))
    }
}

/// The positional encoding of the rows of `x` ([`Op::Encode`]).
fn encode(x: &Array2<f32>, frequencies: u32) -> Array2<f32> {
    let d = x.ncols();
    let mut e = Array2::<f32>::zeros((x.nrows(), d * (1 + 2 * frequencies as usize)));
    e.slice_axis_mut(Axis(1), Slice::from(..d)).assign(x);
    for k in 0..frequencies as usize {
        let scaled = x.mapv(|z| z * (1u32 << k) as f32);
        let at = d * (1 + 2 * k);
        e.slice_axis_mut(Axis(1), Slice::from(at..at + d))
            .assign(&scaled.mapv(f32::sin));
        e.slice_axis_mut(Axis(1), Slice::from(at + d..at + 2 * d))
            .assign(&scaled.mapv(f32::cos));
    }
    e
}

/// The gradient at `x` of the encoding ([`encode`]) given the gradient `g` at its output.
fn encode_backward(x: &Array2<f32>, g: &Array2<f32>, frequencies: u32) -> Array2<f32> {
    let d = x.ncols();
    let mut out = g.slice_axis(Axis(1), Slice::from(..d)).to_owned();
    for k in 0..frequencies as usize {
        let f = (1u32 << k) as f32;
        let at = d * (1 + 2 * k);
        let g_sin = g.slice_axis(Axis(1), Slice::from(at..at + d));
        let g_cos = g.slice_axis(Axis(1), Slice::from(at + d..at + 2 * d));
        ndarray::Zip::from(&mut out)
            .and(x)
            .and(g_sin)
            .and(g_cos)
            .for_each(|o, &z, &gs, &gc| {
                let (sin, cos) = (f * z).sin_cos();
                *o += f * (cos * gs - sin * gc);
            });
    }
    out
}

fn to_rows(points: &[DVec3]) -> Array2<f32> {
    Array2::from_shape_fn((points.len(), 3), |(i, j)| points[i][j] as f32)
}

impl Sdf for Mlp {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        self.counter.add_values(points.len());
        points
            .par_chunks(CHUNK)
            .zip(values.par_chunks_mut(CHUNK))
            .for_each(|(p, out)| {
                let (f, _) = self.forward(to_rows(p), false);
                for (o, f) in out.iter_mut().zip(f) {
                    *o = f as f64;
                }
            });
    }

    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        self.counter.add_gradients(points.len());
        points
            .par_chunks(CHUNK)
            .zip(values.par_chunks_mut(CHUNK))
            .zip(gradients.par_chunks_mut(CHUNK))
            .for_each(|((p, out), grad)| {
                let (f, g) = self.forward(to_rows(p), true);
                let g = g.expect("asked for the gradient");
                for (i, (o, f)) in out.iter_mut().zip(f).enumerate() {
                    *o = f as f64;
                    grad[i] = DVec3::new(g[[i, 0]] as f64, g[[i, 1]] as f64, g[[i, 2]] as f64);
                }
            });
    }

    fn evaluations(&self) -> SdfEvaluations {
        self.counter.get()
    }
}

/// Reads one tensor as f32 (f32 or f64 on file) with `D` dimensions, checking every value is
/// finite.
fn read_tensor<R: Read + Seek, D: Dimension>(
    npz: &mut NpzReader<R>,
    name: &str,
) -> Result<ndarray::Array<f32, D>, SdfError> {
    let bad = |m: String| SdfError::Network(m);
    let any: ArrayD<f32> = match npz.by_name::<_, ndarray::IxDyn>(name) {
        Ok(a) => a,
        Err(first) => match npz.by_name::<ndarray::OwnedRepr<f64>, ndarray::IxDyn>(name) {
            Ok(a) => a.mapv(|v| v as f32),
            Err(_) => return Err(bad(format!("{name}: unreadable ({first})"))),
        },
    };
    if let Some((index, value)) = any.indexed_iter().find(|(_, v)| !v.is_finite()) {
        return Err(bad(format!("{name} holds {value} at {:?}", index.slice())));
    }
    let shape = any.shape().to_vec();
    any.into_dimensionality::<D>().map_err(|_| {
        bad(format!(
            "{name} has shape {shape:?}; expected {} dimensions",
            D::NDIM.unwrap_or(0)
        ))
    })
}
