//! A signed distance function as a [`Shape`] (`docs/sdf.md`): the input kind `roar reconstruct`
//! reads from `.npz` and `.safetensors` networks, `.sdf.toml` files and `.npy` grids (`roar_sdf`).
//!
//! In rig coordinates (the bounds' centre at the origin, their corners on the rig's sphere): the
//! target renders are traced normal maps of the zero set (`roar_sdf::trace`); the initial mesh is
//! the voxel init of `f < 0` on a `sdf_init_resolution` grid over the bounds (supplementary §3),
//! decimated to `init_max_faces`; the point cloud is samples of that init projected onto the zero
//! set along the gradient; the Face Split projector steps along each sample's normal onto the zero
//! set (`roar_sdf::SdfProjector`); and the shape offers its field to the SDF loss.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use roar_loss::{LossError, PointCloud};

use crate::shape::{EnclosureFigures, InitialMesh, Shape, ShapeError};
use roar_mesh::Mesh;
use roar_mesh::spatial::{
    Aabb, Normalization, Projector, RIG_RADIUS, Sdf, SdfEvaluations, sample_surface,
};
use roar_ops::init::{InitialMeshOptions, SdfInitOptions, initial_mesh_from_init, sdf_init};
use roar_render::{Camera, Image};
use roar_sdf::{RigSdf, SdfProjector, SdfProjectorOptions, TraceOptions, TraceStats};
use serde::Serialize;

use crate::config::ReconstructConfig;

/// The bounds an SDF input is reconstructed in when none are given: `[-1.1, 1.1]³`.
pub const DEFAULT_BOUNDS: Aabb = roar_sdf::DEFAULT_BOUNDS;

/// Evaluations of an SDF input's field by what asked for them, for reports.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SdfReport {
    /// Points evaluated for values, by stage: `trace` (the target renders), `init` (the voxel
    /// init), `point_cloud`, `loop` (the SDF loss, the Face Split projector and the finish's fit
    /// to the zero set), and `preview` (the `--preview` picture's input views, when asked for).
    pub values: BTreeMap<&'static str, u64>,
    /// Points evaluated for values and gradients, by the same stages.
    pub gradients: BTreeMap<&'static str, u64>,
    /// The tracer's figures (rays, hits, seconds).
    pub trace_rays: usize,
    /// Rays that hit the zero set.
    pub trace_hits: usize,
    /// Brackets the field did not confirm (left as background).
    pub trace_unconfirmed: usize,
    /// Seconds of the tracing.
    pub trace_seconds: f64,
}

/// A signed distance function (negative inside) with the bounds to reconstruct it in.
pub struct SdfShape {
    name: String,
    field: Arc<dyn Sdf>,
    bounds: Aabb,
    rig: Arc<RigSdf>,
    projector: SdfProjector,
    config: ReconstructConfig,
    /// The rig and its renders, made by [`Shape::prepare`].
    renders: Option<(Vec<Camera>, Vec<Image>)>,
    /// Evaluations so far, by stage (a lock: `Shape` methods take `&self`).
    counts: Mutex<Vec<(&'static str, SdfEvaluations)>>,
    trace: Mutex<TraceStats>,
}

impl SdfShape {
    /// The field `field` in the input's coordinates, reconstructed inside `bounds` (which must
    /// have a positive extent along every axis and hold the zero set).
    pub fn new(
        name: impl Into<String>,
        field: Arc<dyn Sdf>,
        bounds: Aabb,
        config: &ReconstructConfig,
    ) -> Self {
        let normalization = Normalization {
            center: bounds.center(),
            scale: RIG_RADIUS / (0.5 * bounds.diagonal()).max(f64::MIN_POSITIVE),
        };
        let rig = Arc::new(RigSdf {
            inner: field.clone(),
            normalization,
        });
        let projector = SdfProjector {
            sdf: rig.clone(),
            options: SdfProjectorOptions {
                steps: config.target.sdf_projection_steps,
                tolerance: config.target.sdf_projection_tolerance,
            },
        };
        Self {
            name: name.into(),
            field,
            bounds,
            rig,
            projector,
            config: config.clone(),
            renders: None,
            counts: Mutex::new(Vec::new()),
            trace: Mutex::new(TraceStats::default()),
        }
    }

    /// The field in the input's coordinates.
    pub fn field(&self) -> &Arc<dyn Sdf> {
        &self.field
    }

    /// The bounds in rig coordinates.
    fn rig_bounds(&self) -> Aabb {
        let n = self.rig.normalization;
        Aabb {
            min: n.apply(self.bounds.min),
            max: n.apply(self.bounds.max),
        }
    }

    /// Runs `work`, charging the field's evaluations meanwhile to `stage`.
    fn counted<T>(&self, stage: &'static str, work: impl FnOnce() -> T) -> T {
        let before = self.field.evaluations();
        let out = work();
        let after = self.field.evaluations();
        let delta = SdfEvaluations {
            values: after.values - before.values,
            gradients: after.gradients - before.gradients,
        };
        if let Ok(mut counts) = self.counts.lock() {
            counts.push((stage, delta));
        }
        out
    }

    fn trace(&self, cameras: &[Camera]) -> Vec<Image> {
        let options = TraceOptions {
            grid_resolution: self.config.target.sdf_trace_grid,
            refine_steps: self.config.target.sdf_trace_refine_steps,
        };
        let (images, stats) = self.counted("trace", || {
            roar_sdf::trace_normal_maps(self.rig.as_ref(), &self.rig_bounds(), cameras, &options)
        });
        if let Ok(mut trace) = self.trace.lock() {
            trace.rays += stats.rays;
            trace.hits += stats.hits;
            trace.unconfirmed += stats.unconfirmed;
            trace.seconds += stats.seconds;
        }
        images
    }

    /// Normal maps of the zero set seen by `cameras` (rig coordinates: the frame of
    /// [`Shape::normalization`]), traced as the target renders are; for the preview picture.
    /// The field's evaluations are charged to stage `preview`.
    pub fn preview_views(&self, cameras: &[Camera]) -> Vec<Image> {
        let options = TraceOptions {
            grid_resolution: self.config.target.sdf_trace_grid,
            refine_steps: self.config.target.sdf_trace_refine_steps,
        };
        self.counted("preview", || {
            roar_sdf::trace_normal_maps(self.rig.as_ref(), &self.rig_bounds(), cameras, &options).0
        })
    }

    /// The field's evaluations by stage so far, for the report (what no stage claimed is
    /// charged to `loop`).
    pub fn report(&self) -> SdfReport {
        let mut report = SdfReport::default();
        let total = self.field.evaluations();
        let (mut values, mut gradients) = (0, 0);
        if let Ok(counts) = self.counts.lock() {
            for (stage, e) in counts.iter() {
                *report.values.entry(stage).or_default() += e.values;
                *report.gradients.entry(stage).or_default() += e.gradients;
                values += e.values;
                gradients += e.gradients;
            }
        }
        report.values.insert("loop", total.values - values);
        report.gradients.insert("loop", total.gradients - gradients);
        if let Ok(trace) = self.trace.lock() {
            report.trace_rays = trace.rays;
            report.trace_hits = trace.hits;
            report.trace_unconfirmed = trace.unconfirmed;
            report.trace_seconds = trace.seconds;
        }
        report
    }
}

impl Shape for SdfShape {
    fn name(&self) -> &str {
        &self.name
    }

    /// Traces the target renders for `cameras` (the costly step: a grid of values, then a few
    /// evaluations per pixel that sees the surface).
    fn prepare(&mut self, cameras: &[Camera]) -> Result<(), ShapeError> {
        let images = self.trace(cameras);
        if !images.iter().flatten().any(|p| p[3] > 0.0) {
            return Err(ShapeError::Loss(LossError::InvalidTarget(format!(
                "{}: no camera sees the zero set inside the bounds (is f negative inside?)",
                self.name
            ))));
        }
        self.renders = Some((cameras.to_vec(), images));
        Ok(())
    }

    fn normalization(&self) -> Normalization {
        self.rig.normalization
    }

    fn initial_mesh(&self) -> Result<InitialMesh, ShapeError> {
        let bounds = self.rig_bounds();
        let options = SdfInitOptions {
            resolution: self.config.init.sdf_init_resolution,
            ..SdfInitOptions::default()
        };
        let init = self
            .counted("init", || {
                sdf_init(self.rig.as_ref(), bounds.min, bounds.max, &options)
            })
            .map_err(|e| ShapeError::Init(format!("{}: {e}", self.name)))?;
        let raw_faces = init.triangles.len();
        let options = InitialMeshOptions {
            max_faces: self.config.init.init_max_faces,
            ..InitialMeshOptions::default()
        };
        let (mesh, _) = initial_mesh_from_init(init, 0.0, &options)
            .map_err(|e| ShapeError::Init(e.to_string()))?;
        Ok(InitialMesh {
            mesh,
            raw_faces,
            enclosure: EnclosureFigures::default(),
            merged: Default::default(),
        })
    }

    fn point_cloud(&self, initial: &Mesh) -> Result<PointCloud, ShapeError> {
        let (positions, triangles) = initial.to_triangles();
        let samples = sample_surface(
            &positions,
            &triangles,
            self.config.target.point_cloud_samples,
            self.config.seed,
        );
        let (points, normals) = self.counted("point_cloud", || {
            roar_sdf::project_samples(
                self.rig.as_ref(),
                samples.points,
                self.config.target.sdf_projection_steps,
                self.config.target.sdf_projection_tolerance,
            )
        });
        if points.is_empty() {
            return Err(ShapeError::Loss(LossError::InvalidTarget(format!(
                "{}: no sample converged onto the zero set",
                self.name
            ))));
        }
        Ok(PointCloud { points, normals })
    }

    fn target_renders(&self, cameras: &[Camera]) -> Result<Cow<'_, [Image]>, ShapeError> {
        match &self.renders {
            Some((rig, images)) if rig == cameras => Ok(Cow::Borrowed(images)),
            _ => Ok(Cow::Owned(self.trace(cameras))),
        }
    }

    fn signed_distance(&self) -> Option<Arc<dyn Sdf>> {
        Some(self.rig.clone())
    }

    /// The field's projector ([`SdfProjector`]) unless `sdf_split_projector` is off.
    fn projector(&self) -> Option<&dyn Projector> {
        self.config
            .optimize
            .sdf_split_projector
            .then_some(&self.projector as &dyn Projector)
    }
}
