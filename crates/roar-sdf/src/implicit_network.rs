//! The implicit network of IDR, VolSDF and NeuS (and sdfstudio's, which copies it), read from a
//! PyTorch state dict saved as `.safetensors`, with its architecture in a JSON sidecar of the
//! same stem (`model.safetensors` → `model.json`):
//!
//! ```json
//! { "d_in": 3, "d_hidden": 256, "n_layers": 8, "skip_in": [4], "multires": 6,
//!   "softplus_beta": 100, "output_index": 0, "scale": 1.0,
//!   "prefix": "implicit_network.", "bounds": { "min": [-1, -1, -1], "max": [1, 1, 1] } }
//! ```
//!
//! Only `d_hidden` and `n_layers` are required; the others default as shown (`prefix` is found
//! from the tensor names when it is unique, `bounds` default to the SDF default).
//!
//! The network, as those projects write it: `x ← scale·x`; the encoding `e = (x, sin 2⁰x,
//! cos 2⁰x, …, sin 2ᵏ⁻¹x, cos 2ᵏ⁻¹x)` with `k = multires`; then `n_layers + 1` linear layers
//! `linL` (`h ← h·Wᵀ + b`, W out × in), the ones in `skip_in` taking `(h, e)/√2`, softplus with
//! β between them; the last gives the SDF followed by features: `f = out[output_index] / scale`.
//! Widths: `linL` maps `d_hidden` to `d_hidden` (layer 0 takes `e`), except that a layer before
//! a skip gives `d_hidden − |e|` so that the concatenation is `d_hidden` wide again.
//! Weights come as `weight`, as `weight_g`/`weight_v` (`torch.nn.utils.weight_norm`) or as
//! `parametrizations.weight.original0`/`original1` (its successor), `W = g·v/|v|` row by row.

use std::collections::BTreeSet;
use std::path::Path;

use ndarray::{Array1, Array2};
use roar_mesh::spatial::Aabb;
use safetensors::{Dtype, SafeTensors};
use serde::Deserialize;

use crate::error::SdfError;
use crate::grid::BoundsSpec;
use crate::network::{Activation, Mlp, Op};

/// The architecture sidecar of a `.safetensors` network ([module docs](self)).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Architecture {
    #[serde(default = "three")]
    d_in: usize,
    d_hidden: usize,
    n_layers: usize,
    #[serde(default)]
    skip_in: Vec<usize>,
    #[serde(default)]
    multires: u32,
    #[serde(default = "hundred")]
    softplus_beta: f32,
    #[serde(default)]
    output_index: usize,
    #[serde(default = "one")]
    scale: f32,
    #[serde(default)]
    prefix: Option<String>,
    #[serde(default)]
    bounds: Option<BoundsSpec>,
}

fn three() -> usize {
    3
}
fn hundred() -> f32 {
    100.0
}
fn one() -> f32 {
    1.0
}

/// Reads the network at `path` and its sidecar; returns it with the sidecar's bounds, if any.
/// Every malformed file gives a one-line [`SdfError::Network`] naming the tensor or field.
pub fn read_implicit_network(path: &Path) -> Result<(Mlp, Option<Aabb>), SdfError> {
    let sidecar = crate::grid::sidecar_path(path);
    let text = std::fs::read_to_string(&sidecar).map_err(|e| {
        SdfError::Network(format!(
            "{}: {e} (a .safetensors network needs its architecture there: \
             {{\"d_hidden\": …, \"n_layers\": …, \"skip_in\": […], \"multires\": …}})",
            sidecar.display()
        ))
    })?;
    let architecture: Architecture = serde_json::from_str(&text)
        .map_err(|e| SdfError::Network(format!("{}: {e}", sidecar.display())))?;
    let bounds = match &architecture.bounds {
        Some(spec) => Some(
            spec.to_aabb()
                .map_err(|e| SdfError::Network(format!("{}: {e}", sidecar.display())))?,
        ),
        None => None,
    };
    let bytes =
        std::fs::read(path).map_err(|e| SdfError::Io(format!("{}: {e}", path.display())))?;
    let mlp = implicit_network(&bytes, &architecture)
        .map_err(|e| SdfError::Network(format!("{}: {e}", path.display())))?;
    Ok((mlp, bounds))
}

/// The network of `architecture` from the state dict in `bytes`; errors are one line.
fn implicit_network(bytes: &[u8], architecture: &Architecture) -> Result<Mlp, String> {
    let Architecture {
        d_in,
        d_hidden,
        n_layers,
        ref skip_in,
        multires,
        softplus_beta,
        output_index,
        scale,
        ..
    } = *architecture;
    if d_in != 3 {
        return Err(format!("d_in is {d_in}; an SDF of space takes 3"));
    }
    if !(softplus_beta.is_finite() && softplus_beta > 0.0) {
        return Err(format!(
            "softplus_beta is {softplus_beta}; it must be above 0"
        ));
    }
    if !(scale.is_finite() && scale > 0.0) {
        return Err(format!("scale is {scale}; it must be above 0"));
    }
    if multires > 16 {
        return Err(format!("multires is {multires}; at most 16 frequencies"));
    }
    if let Some(l) = skip_in.iter().find(|&&l| l == 0 || l > n_layers) {
        return Err(format!(
            "skip_in holds {l}; skips go into layers 1..={n_layers}"
        ));
    }
    let tensors =
        SafeTensors::deserialize(bytes).map_err(|e| format!("not a safetensors file: {e}"))?;
    let prefix = match &architecture.prefix {
        Some(prefix) => prefix.clone(),
        None => find_prefix(&tensors)?,
    };
    let encoded = d_in * (1 + 2 * multires as usize);
    let skips: BTreeSet<usize> = skip_in.iter().copied().collect();
    if !skips.is_empty() && d_hidden <= encoded {
        return Err(format!(
            "d_hidden {d_hidden} leaves no room for the {encoded} encoded inputs a skip appends"
        ));
    }
    let mut ops = Vec::new();
    if scale != 1.0 {
        ops.push(Op::Scale(scale));
    }
    ops.push(Op::Encode {
        frequencies: multires,
    });
    for l in 0..=n_layers {
        let inputs = if l == 0 { encoded } else { d_hidden };
        let outputs = if l == n_layers {
            None
        } else if skips.contains(&(l + 1)) {
            Some(d_hidden - encoded)
        } else {
            Some(d_hidden)
        };
        let (w, b) = linear(&tensors, &format!("{prefix}lin{l}"), inputs, outputs)?;
        if skips.contains(&l) {
            ops.push(Op::ConcatEncoded);
        }
        if l < n_layers {
            ops.push(Op::Dense {
                a: w.reversed_axes(),
                b,
            });
            ops.push(Op::Activation(Activation::Softplus {
                beta: softplus_beta,
            }));
        } else {
            if output_index >= w.nrows() {
                return Err(format!(
                    "output_index is {output_index} but {prefix}lin{l} gives {} outputs",
                    w.nrows()
                ));
            }
            // Only the SDF column of the last layer is needed.
            let row = w.row(output_index).to_owned();
            let a = row.into_shape_with_order((w.ncols(), 1)).expect("a column");
            ops.push(Op::Dense {
                a,
                b: Array1::from_elem(1, b[output_index]),
            });
        }
    }
    if scale != 1.0 {
        ops.push(Op::Scale(1.0 / scale));
    }
    Ok(Mlp::from_ops(ops))
}

/// The one prefix (e.g. `implicit_network.`) under which the state dict holds `lin0.bias`.
fn find_prefix(tensors: &SafeTensors) -> Result<String, String> {
    let candidates: Vec<String> = tensors
        .names()
        .into_iter()
        .filter_map(|n| n.strip_suffix("lin0.bias").map(str::to_string))
        .filter(|p| p.is_empty() || p.ends_with('.'))
        .collect();
    match candidates.as_slice() {
        [one] => Ok(one.clone()),
        [] => Err(
            "no lin0.bias tensor: not an IDR/VolSDF/NeuS implicit network \
                   (or give its \"prefix\" in the sidecar)"
                .into(),
        ),
        many => Err(format!(
            "several networks ({}); give the sidecar a \"prefix\"",
            many.join(", ")
        )),
    }
}

/// The weight (out × in) and bias of linear layer `key`, checked against `inputs` and, when
/// given, `outputs`.
fn linear(
    tensors: &SafeTensors,
    key: &str,
    inputs: usize,
    outputs: Option<usize>,
) -> Result<(Array2<f32>, Array1<f32>), String> {
    let has = |suffix: &str| tensors.tensor(&format!("{key}.{suffix}")).is_ok();
    let (weight_name, w) = if has("weight") {
        let name = format!("{key}.weight");
        let w = matrix(tensors, &name)?;
        (name, w)
    } else {
        let (g_name, v_name) = if has("weight_g") || has("weight_v") {
            (format!("{key}.weight_g"), format!("{key}.weight_v"))
        } else if has("parametrizations.weight.original0") {
            (
                format!("{key}.parametrizations.weight.original0"),
                format!("{key}.parametrizations.weight.original1"),
            )
        } else {
            return Err(format!(
                "{key}.weight is missing (nor weight_g/weight_v, nor \
                 parametrizations.weight.original0/original1)"
            ));
        };
        let v = matrix(tensors, &v_name)?;
        let g = values(tensors, &g_name)?;
        if g.len() != v.nrows() {
            return Err(format!(
                "{g_name} has {} values but {v_name} has {} rows",
                g.len(),
                v.nrows()
            ));
        }
        let mut w = v;
        for (mut row, g) in w.rows_mut().into_iter().zip(g.iter()) {
            let norm = row.dot(&row).sqrt();
            if norm == 0.0 {
                return Err(format!(
                    "{v_name} has a zero row: its direction is undefined"
                ));
            }
            row.mapv_inplace(|x| x * g / norm);
        }
        (v_name, w)
    };
    if w.ncols() != inputs {
        return Err(format!(
            "{weight_name} is {} × {} but the layer takes {inputs} inputs",
            w.nrows(),
            w.ncols()
        ));
    }
    if let Some(outputs) = outputs.filter(|&o| o != w.nrows()) {
        return Err(format!(
            "{weight_name} is {} × {} but the layer gives {outputs} outputs",
            w.nrows(),
            w.ncols()
        ));
    }
    let bias_name = format!("{key}.bias");
    let b = Array1::from(values(tensors, &bias_name)?);
    if b.len() != w.nrows() {
        return Err(format!(
            "{bias_name} has {} values but {weight_name} has {} rows",
            b.len(),
            w.nrows()
        ));
    }
    Ok((w, b))
}

/// Tensor `name` as a matrix.
fn matrix(tensors: &SafeTensors, name: &str) -> Result<Array2<f32>, String> {
    let view = tensors
        .tensor(name)
        .map_err(|_| format!("{name} is missing"))?;
    let &[rows, cols] = view.shape() else {
        return Err(format!(
            "{name} has shape {:?}; expected 2 dimensions",
            view.shape()
        ));
    };
    Ok(Array2::from_shape_vec((rows, cols), values(tensors, name)?).expect("rows × cols values"))
}

/// The values of tensor `name` (f32, f64, f16 or bf16 on file), each checked finite.
fn values(tensors: &SafeTensors, name: &str) -> Result<Vec<f32>, String> {
    let view = tensors
        .tensor(name)
        .map_err(|_| format!("{name} is missing"))?;
    let data = view.data();
    let values: Vec<f32> = match view.dtype() {
        Dtype::F32 => data
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect(),
        Dtype::F64 => data
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")) as f32)
            .collect(),
        Dtype::F16 => data
            .chunks_exact(2)
            .map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32())
            .collect(),
        Dtype::BF16 => data
            .chunks_exact(2)
            .map(|b| half::bf16::from_le_bytes([b[0], b[1]]).to_f32())
            .collect(),
        other => return Err(format!("{name} is {other:?}; expected a float tensor")),
    };
    if let Some((index, value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(format!("{name} holds {value} at flat index {index}"));
    }
    Ok(values)
}
