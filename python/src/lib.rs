//! `roar._roar`: the compiled half of the Python package.
//!
//! The Python half (`python/roar/__init__.py`) checks and converts the numpy arrays and hands
//! them over as little-endian bytes (`<f8` positions, `<u4` triangles); this half decodes them,
//! runs roar with the GIL released and hands bytes and JSON back. Every error is a one-line
//! message, as the CLI prints it: `ValueError` for unusable input or config, `roar.RoarError`
//! for a failure of the work itself, `KeyboardInterrupt` (or the callback's own exception) when
//! the progress check stopped the run.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use glam::DVec3;
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use roar::{PipelineError, Progress, ReconstructConfig, Reconstruction, SdfShape, SoupShape};
use roar_eval::{EvalError, EvalOptions};
use roar_io::TriangleSoup;
use roar_mesh::Mesh;
use roar_mesh::spatial::{Aabb, Sdf, SdfCounter, SdfEvaluations};

create_exception!(
    _roar,
    RoarError,
    PyRuntimeError,
    "roar could not do the work asked (the message is the CLI's)."
);

/// Points as `<f8` bytes, x, y, z in turn, as the Python half reads `(n, 3)` arrays.
fn points_to_bytes(points: &[DVec3]) -> Vec<u8> {
    points
        .iter()
        .flat_map(|v| v.to_array())
        .flat_map(f64::to_le_bytes)
        .collect()
}

/// The `f64`s of `<f8` bytes (a trailing partial number is dropped).
fn f64s_from_bytes(bytes: &[u8]) -> impl Iterator<Item = f64> + '_ {
    bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8-byte chunk")))
}

/// Positions and triangles decoded from the bytes the Python half sends.
fn soup_from_bytes(positions: &[u8], triangles: &[u8]) -> PyResult<TriangleSoup> {
    if !positions.len().is_multiple_of(24) || !triangles.len().is_multiple_of(12) {
        return Err(PyValueError::new_err(
            "internal: position or triangle bytes are not whole rows",
        ));
    }
    let u = |c: &[u8]| u32::from_le_bytes(c.try_into().expect("4-byte chunk"));
    let coordinates: Vec<f64> = f64s_from_bytes(positions).collect();
    let positions = coordinates
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect();
    let triangles = triangles
        .chunks_exact(12)
        .map(|r| [u(&r[..4]), u(&r[4..8]), u(&r[8..])])
        .collect();
    let soup = TriangleSoup::new(positions, triangles);
    soup.validate()
        .map_err(|defect| PyValueError::new_err(defect.to_string()))?;
    Ok(soup)
}

/// Positions and triangles as the bytes the Python half turns back into arrays.
fn soup_to_bytes<'py>(
    py: Python<'py>,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> (Bound<'py, PyBytes>, Bound<'py, PyBytes>) {
    let p = points_to_bytes(positions);
    let t: Vec<u8> = triangles
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    (PyBytes::new(py, &p), PyBytes::new(py, &t))
}

fn roar_error(e: impl std::fmt::Display) -> PyErr {
    RoarError::new_err(e.to_string())
}

/// A configuration the Python half sent that roar refuses, with the CLI's message.
fn config_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("config: {e}"))
}

/// The effective config: `defaults`, then the JSON of the user's dict (the CLI's TOML layout),
/// then the face budget; validated like the CLI's.
fn effective_config(
    config_json: &str,
    faces: usize,
    defaults: &ReconstructConfig,
) -> PyResult<ReconstructConfig> {
    let table: toml::Table = serde_json::from_str(config_json).map_err(config_error)?;
    let mut config = ReconstructConfig::from_table(table, defaults).map_err(config_error)?;
    config.faces = faces;
    config.validate().map_err(config_error)?;
    Ok(config)
}

/// Runs the reconstruction (GIL released) and returns `(positions, triangles, report_json)`.
/// `label` names the input in the report and in error messages (a path, or `<arrays>`).
#[pyfunction]
#[pyo3(signature = (positions, triangles, faces, config_json, label, progress=None))]
fn reconstruct<'py>(
    py: Python<'py>,
    positions: &[u8],
    triangles: &[u8],
    faces: usize,
    config_json: &str,
    label: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>, String)> {
    let soup = soup_from_bytes(positions, triangles)?;
    let config = effective_config(config_json, faces, &ReconstructConfig::default())?;
    run_reconstruction(py, &soup, config, label, progress)
}

/// A field given by the Python half's `field(points, with_gradient)`, which calls the user's
/// callables on the `<f8` bytes of `(n, 3)` points, checks what they return and gives back the
/// bytes of `n` values (then `3n` gradient components when asked).
struct PyField {
    call: Py<PyAny>,
    /// Whether the user gave a gradient; without one, the sampler differences its samples (the
    /// only caller of the field: `sdf_sample = false` is refused without a gradient).
    has_gradient: bool,
    counter: SdfCounter,
    /// The first exception the callables raised. Calls are made one at a time (under this
    /// lock); after an exception no batch is sent and every value reads NaN, which stops the run.
    error: Mutex<Option<PyErr>>,
}

impl PyField {
    /// Fills `values` (and `gradients` when given) at `points` by one call of the Python half.
    fn call(&self, points: &[DVec3], values: &mut [f64], gradients: Option<&mut [DVec3]>) {
        let mut error = self.error.lock().unwrap_or_else(|e| e.into_inner());
        if error.is_none() {
            let with_gradient = gradients.is_some();
            let bytes = points_to_bytes(points);
            let returned = Python::attach(|py| -> PyResult<Vec<f64>> {
                let out = self
                    .call
                    .call1(py, (PyBytes::new(py, &bytes), with_gradient))?;
                Ok(f64s_from_bytes(out.bind(py).cast::<PyBytes>()?.as_bytes()).collect())
            });
            let n = points.len();
            match returned {
                Ok(out) if out.len() == if with_gradient { 4 * n } else { n } => {
                    values.copy_from_slice(&out[..n]);
                    if let Some(gradients) = gradients {
                        for (i, g) in gradients.iter_mut().enumerate() {
                            *g = DVec3::new(out[n + 3 * i], out[n + 3 * i + 1], out[n + 3 * i + 2]);
                        }
                    }
                    return;
                }
                Ok(out) => {
                    *error = Some(PyRuntimeError::new_err(format!(
                        "internal: the field gave {} numbers for {n} points",
                        out.len()
                    )))
                }
                Err(e) => *error = Some(e),
            }
        }
        values.fill(f64::NAN);
    }
}

impl Sdf for PyField {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        self.counter.add_values(points.len());
        self.call(points, values, None);
    }

    /// Without the user's gradient this is a bug of roar's: it records an internal error (the
    /// run stops on the NaN values) rather than guess.
    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        if !self.has_gradient {
            let mut error = self.error.lock().unwrap_or_else(|e| e.into_inner());
            error.get_or_insert_with(|| {
                PyRuntimeError::new_err("internal: a field without `gradient` was asked for one")
            });
            values.fill(f64::NAN);
            return;
        }
        self.counter.add_gradients(points.len());
        self.call(points, values, Some(gradients));
    }

    fn evaluations(&self) -> SdfEvaluations {
        self.counter.get()
    }

    fn has_gradient(&self) -> bool {
        self.has_gradient
    }
}

/// Reconstructs the zero set of a Python field inside `bounds` (`(min, max)`, checked by the
/// Python half) and returns `(positions, triangles, report_json)`. `field` is the Python
/// half's checked caller of the user's callables ([`PyField`]); an exception of theirs wins
/// over the pipeline's error.
#[pyfunction]
#[pyo3(signature = (field, has_gradient, bounds, faces, config_json, progress=None))]
fn reconstruct_sdf<'py>(
    py: Python<'py>,
    field: Py<PyAny>,
    has_gradient: bool,
    bounds: ([f64; 3], [f64; 3]),
    faces: usize,
    config_json: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>, String)> {
    let config = effective_config(config_json, faces, &ReconstructConfig::sdf_defaults())?;
    if !has_gradient && !config.target.sdf_sample {
        return Err(config_error(
            "target.sdf_sample = false has every stage evaluate the field's gradient: give `gradient`",
        ));
    }
    let bounds = Aabb {
        min: DVec3::from_array(bounds.0),
        max: DVec3::from_array(bounds.1),
    };
    let field = Arc::new(PyField {
        call: field,
        has_gradient,
        counter: SdfCounter::default(),
        error: Mutex::new(None),
    });
    let label = "<function>";
    let started = std::time::Instant::now();
    let outcome = with_progress(py, &config, progress, |reconstruction, on_progress| {
        let mut shape = SdfShape::new(label, field.clone(), bounds, &config);
        let result = reconstruction.run(&mut shape, on_progress)?;
        let output_metrics = roar_eval::evaluate(
            &result.positions,
            &result.triangles,
            None,
            &EvalOptions::default(),
        )?;
        Ok::<_, RunError>((result, shape.report(), output_metrics))
    })?;
    if let Some(e) = field.error.lock().unwrap_or_else(|e| e.into_inner()).take() {
        return Err(e);
    }
    let (result, sdf, output_metrics) =
        outcome.map_err(|e| roar_error(format!("{label}: reconstruction failed: {e}")))?;
    let report = serde_json::json!({
        "input": label,
        "seed": config.seed,
        "seconds_total": started.elapsed().as_secs_f64(),
        "output_metrics": output_metrics,
        "run": result.stats,
        "config": config,
        "sdf": sdf,
    });
    let (p, t) = soup_to_bytes(py, &result.positions, &result.triangles);
    Ok((p, t, report.to_string()))
}

/// Reads a mesh file of any format the CLI reads (OBJ, PLY, STL, OFF, glTF) and returns
/// `(positions, triangles)`.
#[pyfunction]
fn read_mesh<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>)> {
    let soup = py
        .detach(|| roar_io::read_mesh(&path))
        .map_err(roar_error)?;
    Ok(soup_to_bytes(py, &soup.positions, &soup.triangles))
}

/// Writes a mesh atomically, format by extension (as the CLI writes its output).
#[pyfunction]
fn write_mesh(py: Python<'_>, path: PathBuf, positions: &[u8], triangles: &[u8]) -> PyResult<()> {
    let soup = soup_from_bytes(positions, triangles)?;
    py.detach(|| roar_io::write_mesh(&path, &soup))
        .map_err(roar_error)
}

/// Why a run of [`run_reconstruction`] failed: the pipeline, or the metrics of its input or output
/// (a bug: both are valid soups by then).
#[derive(Debug)]
enum RunError {
    Pipeline(PipelineError),
    Eval(EvalError),
}

impl From<PipelineError> for RunError {
    fn from(e: PipelineError) -> Self {
        RunError::Pipeline(e)
    }
}

impl From<EvalError> for RunError {
    fn from(e: EvalError) -> Self {
        RunError::Eval(e)
    }
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunError::Pipeline(e) => e.fmt(f),
            RunError::Eval(e) => write!(f, "internal: {e}"),
        }
    }
}

/// Runs `work` on a [`Reconstruction`] of `config` with the GIL released, calling the user's
/// `progress` and checking for Ctrl-C at every report; the first exception of either stops the
/// run and is returned as the error, else `work`'s result.
fn with_progress<T: Send>(
    py: Python<'_>,
    config: &ReconstructConfig,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(&mut Reconstruction, &mut dyn FnMut(&Progress)) -> T + Send,
) -> PyResult<T> {
    let cancel = Arc::new(AtomicBool::new(false));
    let mut stopped_by: Option<PyErr> = None;
    let outcome = py.detach(|| {
        let mut reconstruction = Reconstruction::new(config.clone());
        reconstruction.cancel = Some(cancel.clone());
        let mut on_progress = |p: &Progress| {
            if stopped_by.is_some() {
                return;
            }
            // Once per report: the user's callback, then pending signals (Ctrl-C).
            let checked = Python::attach(|py| -> PyResult<()> {
                if let Some(callback) = &progress {
                    let record = PyDict::new(py);
                    record.set_item("stage", p.stage)?;
                    record.set_item("iteration", p.iteration)?;
                    record.set_item("iterations", p.iterations)?;
                    record.set_item("loss", p.loss)?;
                    record.set_item("faces", p.faces)?;
                    callback.call1(py, (record,))?;
                }
                py.check_signals()
            });
            if let Err(e) = checked {
                stopped_by = Some(e);
                cancel.store(true, Ordering::Relaxed);
            }
        };
        work(&mut reconstruction, &mut on_progress)
    });
    match stopped_by {
        Some(e) => Err(e),
        None => Ok(outcome),
    }
}

fn run_reconstruction<'py>(
    py: Python<'py>,
    soup: &TriangleSoup,
    config: ReconstructConfig,
    label: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>, String)> {
    let started = std::time::Instant::now();
    let outcome = with_progress(py, &config, progress, |reconstruction, on_progress| {
        let mut shape = SoupShape::new(label, &soup.positions, &soup.triangles, &config);
        let result = reconstruction.run(&mut shape, on_progress)?;
        drop(shape);
        let eval_input = EvalOptions {
            self_intersections: None,
            ..EvalOptions::default()
        };
        let input_metrics =
            roar_eval::evaluate(&soup.positions, &soup.triangles, None, &eval_input)?;
        let output_metrics = roar_eval::evaluate(
            &result.positions,
            &result.triangles,
            Some((&soup.positions, &soup.triangles)),
            &EvalOptions::default(),
        )?;
        Ok::<_, RunError>((result, input_metrics, output_metrics))
    })?;
    let (result, input_metrics, output_metrics) =
        outcome.map_err(|e| roar_error(format!("{label}: reconstruction failed: {e}")))?;
    let report = serde_json::json!({
        "input": label,
        "seed": config.seed,
        "seconds_total": started.elapsed().as_secs_f64(),
        "input_metrics": input_metrics,
        "output_metrics": output_metrics,
        "run": result.stats,
        "config": config,
    });
    let (p, t) = soup_to_bytes(py, &result.positions, &result.triangles);
    Ok((p, t, report.to_string()))
}

/// The metrics report (JSON) of a soup, with fidelity against `reference` when given.
#[pyfunction]
#[pyo3(signature = (positions, triangles, reference=None))]
fn eval(
    py: Python<'_>,
    positions: &[u8],
    triangles: &[u8],
    reference: Option<(Bound<'_, PyBytes>, Bound<'_, PyBytes>)>,
) -> PyResult<String> {
    let soup = soup_from_bytes(positions, triangles)?;
    let reference = reference
        .map(|(p, t)| soup_from_bytes(p.as_bytes(), t.as_bytes()))
        .transpose()?;
    let report = py
        .detach(|| {
            roar_eval::evaluate(
                &soup.positions,
                &soup.triangles,
                reference
                    .as_ref()
                    .map(|r| (r.positions.as_slice(), r.triangles.as_slice())),
                &EvalOptions::default(),
            )
        })
        .map_err(roar_error)?;
    serde_json::to_string(&report).map_err(roar_error)
}

/// The soup welded at bit-identical positions as a closed 2-manifold, or the CLI's message.
fn closed_mesh(soup: &TriangleSoup) -> PyResult<Mesh> {
    let (positions, triangles) = roar::input::welded_referenced(soup);
    Mesh::from_triangles(positions, &triangles).map_err(|e| {
        PyValueError::new_err(format!(
            "the mesh is not a closed, oriented 2-manifold (run roar.init on it first): {e}"
        ))
    })
}

/// The guaranteed QEM of a closed 2-manifold to exactly `faces` faces; returns
/// `(positions, triangles, reached_target)`.
#[pyfunction]
fn decimate<'py>(
    py: Python<'py>,
    positions: &[u8],
    triangles: &[u8],
    faces: usize,
    best_effort: bool,
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>, bool)> {
    let soup = soup_from_bytes(positions, triangles)?;
    let mut mesh = closed_mesh(&soup)?;
    let options = roar_ops::decimate::DecimateOptions {
        best_effort,
        ..roar_ops::decimate::DecimateOptions::default()
    };
    let stats = py
        .detach(|| roar_ops::decimate::decimate_in_parallel(&mut mesh, faces, &options))
        .map_err(roar_error)?;
    let (p, t) = mesh.to_triangles();
    let (p, t) = soup_to_bytes(py, &p, &t);
    Ok((p, t, stats.reached_target))
}

/// The watertight init of any soup, decimated to at most `faces` faces (`resolution` 0: the
/// CLI's default); returns `(positions, triangles)`.
#[pyfunction]
fn init<'py>(
    py: Python<'py>,
    positions: &[u8],
    triangles: &[u8],
    resolution: usize,
    faces: usize,
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>)> {
    let soup = soup_from_bytes(positions, triangles)?;
    roar::budget::check_even_budget(faces).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let (positions, triangles) = roar::input::welded_referenced(&soup);
    let options = roar_ops::init::InitialMeshOptions {
        init: roar_ops::init::InitOptions {
            resolution: if resolution == 0 {
                roar_ops::init::InitOptions::default().resolution
            } else {
                resolution
            },
            ..roar_ops::init::InitOptions::default()
        },
        max_faces: faces,
        ..roar_ops::init::InitialMeshOptions::default()
    };
    let (mesh, _) = py
        .detach(|| roar_ops::init::initial_mesh(&positions, &triangles, &options))
        .map_err(|e| roar_error(format!("watertight init failed: {e}")))?;
    let (p, t) = mesh.to_triangles();
    Ok(soup_to_bytes(py, &p, &t))
}

/// The default configuration as JSON (the CLI's `--print-config`, in JSON).
#[pyfunction]
fn default_config() -> PyResult<String> {
    serde_json::to_string(&ReconstructConfig::default()).map_err(roar_error)
}

/// The compiled module.
#[pymodule]
fn _roar(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("RoarError", m.py().get_type::<RoarError>())?;
    m.add_function(wrap_pyfunction!(reconstruct, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct_sdf, m)?)?;
    m.add_function(wrap_pyfunction!(read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(eval, m)?)?;
    m.add_function(wrap_pyfunction!(decimate, m)?)?;
    m.add_function(wrap_pyfunction!(init, m)?)?;
    m.add_function(wrap_pyfunction!(default_config, m)?)?;
    Ok(())
}
