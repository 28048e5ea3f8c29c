//! A signed distance function as a [`Shape`] (`docs/sdf.md`): the input kind `roar reconstruct`
//! reads from `.npz` and `.safetensors` networks, `.sdf.toml` files and `.npy` grids (`roar_sdf`).
//!
//! In rig coordinates (the bounds' centre at the origin, their corners on the rig's sphere): the
//! field is sampled once, adaptively (`roar_sdf::sampled`, the report's stage `sample`), and
//! every later stage reads the samples instead of the field (unless `sdf_sample` is off); the
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
use roar_sdf::{
    RigSdf, SampleOptions, SampleStats, SampledSdf, SdfProjector, SdfProjectorOptions,
    TraceOptions, TraceStats,
};
use serde::Serialize;

use crate::config::ReconstructConfig;

/// The bounds an SDF input is reconstructed in when none are given: `[-1.1, 1.1]³`.
pub const DEFAULT_BOUNDS: Aabb = roar_sdf::DEFAULT_BOUNDS;

/// Evaluations of an SDF input's field by what asked for them, for reports.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SdfReport {
    /// Points the **field** evaluated for values, by stage: `sample` (the adaptive sampling),
    /// `trace` (the target renders), `init` (the voxel init), `point_cloud`, `loop` (the SDF
    /// loss, the Face Split projector and the finish's fit to the zero set), and `preview` (the
    /// `--preview` picture's input views, when asked for). With the sampling on, every stage
    /// after `sample` reads the samples, so the field's counts are there and nowhere else.
    pub values: BTreeMap<&'static str, u64>,
    /// Points the field evaluated for values and gradients, by the same stages.
    pub gradients: BTreeMap<&'static str, u64>,
    /// Queries of the sampled field (not the field's evaluations) for values, by stage; empty
    /// when the sampling is off.
    pub sampled_values: BTreeMap<&'static str, u64>,
    /// Queries of the sampled field for values and gradients, by stage.
    pub sampled_gradients: BTreeMap<&'static str, u64>,
    /// What the sampling did (absent when it is off).
    pub sample: Option<SampleStats>,
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
    /// The sampled field in rig coordinates, made by [`SdfShape::sample`].
    sampled: Option<Arc<SampledSdf>>,
    sample_stats: Option<SampleStats>,
    projector: SdfProjector,
    config: ReconstructConfig,
    /// The rig and its renders, made by [`Shape::prepare`].
    renders: Option<(Vec<Camera>, Vec<Image>)>,
    /// The field's evaluations and the sampled field's queries so far, by stage (a lock:
    /// `Shape` methods take `&self`).
    counts: Mutex<Vec<(&'static str, SdfEvaluations, SdfEvaluations)>>,
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
            sampled: None,
            sample_stats: None,
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

    /// Samples the field once over the bounds (`roar_sdf::SampledSdf`, charged to stage
    /// `sample`), after which every stage reads the samples; does nothing when the field is
    /// sampled already or `sdf_sample` is off. [`Shape::prepare`] calls it first.
    pub fn sample(&mut self) -> Result<(), ShapeError> {
        if self.sampled.is_some() || !self.config.target.sdf_sample {
            return Ok(());
        }
        let options = sample_options(&self.config);
        let bounds = self.rig_bounds();
        let (sampled, stats) = self
            .counted("sample", || {
                SampledSdf::build(self.rig.as_ref(), bounds, &options)
            })
            .map_err(|e| ShapeError::Field(format!("{}: {e}", self.name)))?;
        let sampled = Arc::new(sampled);
        self.projector.sdf = sampled.clone();
        self.sampled = Some(sampled);
        self.sample_stats = Some(stats);
        Ok(())
    }

    /// What the stages read, in rig coordinates: the samples once made, else the field.
    fn query(&self) -> Arc<dyn Sdf> {
        match &self.sampled {
            Some(sampled) => sampled.clone(),
            None => self.rig.clone(),
        }
    }

    /// The sampled field's queries so far (zeros before the sampling).
    fn queries(&self) -> SdfEvaluations {
        self.sampled
            .as_ref()
            .map(|s| s.evaluations())
            .unwrap_or_default()
    }

    /// The bounds in rig coordinates.
    fn rig_bounds(&self) -> Aabb {
        let n = self.rig.normalization;
        Aabb {
            min: n.apply(self.bounds.min),
            max: n.apply(self.bounds.max),
        }
    }

    /// Runs `work`, charging the field's evaluations and the sampled field's queries meanwhile
    /// to `stage`.
    fn counted<T>(&self, stage: &'static str, work: impl FnOnce() -> T) -> T {
        let (before, queried) = (self.field.evaluations(), self.queries());
        let out = work();
        let field = self.field.evaluations() - before;
        let queries = self.queries() - queried;
        if let Ok(mut counts) = self.counts.lock() {
            counts.push((stage, field, queries));
        }
        out
    }

    fn trace(&self, cameras: &[Camera]) -> Vec<Image> {
        let options = TraceOptions {
            grid_resolution: self.config.target.sdf_trace_grid,
            refine_steps: self.config.target.sdf_trace_refine_steps,
        };
        let (images, stats) = self.counted("trace", || {
            roar_sdf::trace_normal_maps(
                self.query().as_ref(),
                &self.rig_bounds(),
                cameras,
                &options,
            )
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
            roar_sdf::trace_normal_maps(
                self.query().as_ref(),
                &self.rig_bounds(),
                cameras,
                &options,
            )
            .0
        })
    }

    /// The field's evaluations and the sampled field's queries by stage so far, for the report
    /// (what no stage claimed is charged to `loop`).
    pub fn report(&self) -> SdfReport {
        let mut report = SdfReport {
            sample: self.sample_stats,
            ..SdfReport::default()
        };
        if let Ok(counts) = self.counts.lock() {
            (report.values, report.gradients) = by_stage(
                counts.iter().map(|&(stage, field, _)| (stage, field)),
                self.field.evaluations(),
            );
            if self.sampled.is_some() {
                (report.sampled_values, report.sampled_gradients) = by_stage(
                    counts.iter().map(|&(stage, _, queries)| (stage, queries)),
                    self.queries(),
                );
            }
        }
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
        self.sample()?;
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
                sdf_init(self.query().as_ref(), bounds.min, bounds.max, &options)
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
                self.query().as_ref(),
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
        Some(self.query())
    }

    /// The field's projector ([`SdfProjector`]) unless `sdf_split_projector` is off.
    fn projector(&self) -> Option<&dyn Projector> {
        self.config
            .optimize
            .sdf_split_projector
            .then_some(&self.projector as &dyn Projector)
    }
}

/// Counts by stage, values and gradients apart, with what no stage claimed of `total` charged
/// to `loop`.
fn by_stage<'a>(
    counts: impl Iterator<Item = (&'a str, SdfEvaluations)>,
    total: SdfEvaluations,
) -> (BTreeMap<&'a str, u64>, BTreeMap<&'a str, u64>) {
    let (mut values, mut gradients) = (BTreeMap::new(), BTreeMap::new());
    let mut claimed = SdfEvaluations::default();
    for (stage, e) in counts {
        *values.entry(stage).or_default() += e.values;
        *gradients.entry(stage).or_default() += e.gradients;
        claimed.values += e.values;
        claimed.gradients += e.gradients;
    }
    let rest = total - claimed;
    values.insert("loop", rest.values);
    gradients.insert("loop", rest.gradients);
    (values, gradients)
}

/// The sampling's options from the configuration: `sdf_sample_resolution`, or when it is 0 the
/// resolution the face budget needs ([`auto_sample_resolution`]), with the coarse grid
/// [`SampleOptions::for_resolution`] gives and `sdf_sample_band`.
pub fn sample_options(config: &ReconstructConfig) -> SampleOptions {
    let resolution = match config.target.sdf_sample_resolution {
        0 => auto_sample_resolution(config.faces),
        r => r,
    };
    SampleOptions::for_resolution(resolution, config.target.sdf_sample_band)
}

/// The sampling's resolution for a budget of `faces`: 256 up to 10,000 faces, 384 above
/// (`docs/sdf.md`, "Sampling").
pub fn auto_sample_resolution(faces: usize) -> usize {
    if faces <= 10_000 { 256 } else { 384 }
}
