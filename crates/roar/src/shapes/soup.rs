//! The triangle soup as a [`Shape`]: the input kind `roar reconstruct` reads from OBJ, PLY, STL
//! and OFF files.
//!
//! [`SoupShape::prepare`] builds the cleaned target T′ (weld, normalize, twin clean-up by pixel
//! counts; `roar_loss::target`) and its renders; the initial mesh is the watertight voxel init
//! of T′ decimated to `init_max_faces` (`roar_ops::init`); the point cloud is the
//! winding-filtered samples of T′ plus samples on the sharp edges of M0
//! (`docs/method.md#point-cloud`).

use std::borrow::Cow;

use glam::DVec3;
use roar_loss::{
    LossError, PointCloud, PointCloudOptions, SharpEdgeOptions, Target, build_target, point_cloud,
    render_views, sharp_edge_samples, two_sided_faces,
};
use roar_mesh::Mesh;
use roar_mesh::spatial::{Aabb, Normalization};
use roar_ops::init::{InitOptions, InitialMeshOptions, ScannerView};
use roar_render::{Camera, Image};

use crate::budget::{most_pieces, pieces_to_aim_for};
use crate::config::ReconstructConfig;
use crate::rig::target_options;
use crate::shape::{EnclosureFigures, InitialMesh, PieceMerge, Shape, ShapeError, ShapeSummary};

/// A triangle soup (any coordinates, anything goes) and the configuration it is cleaned up,
/// initialised and sampled with.
pub struct SoupShape<'a> {
    name: String,
    positions: &'a [DVec3],
    triangles: &'a [[u32; 3]],
    config: ReconstructConfig,
    /// The scanners the soup was measured from (range scans), in the soup's coordinates.
    scanner_views: Vec<ScannerView>,
    /// T′ and its renders, made by [`Shape::prepare`].
    target: Option<Target>,
}

impl<'a> SoupShape<'a> {
    /// The soup `positions` (#V) and `triangles` (#F indices into `positions`), unchecked until
    /// [`Shape::prepare`], which reports an out-of-range index or a non-finite coordinate.
    pub fn new(
        name: impl Into<String>,
        positions: &'a [DVec3],
        triangles: &'a [[u32; 3]],
        config: &ReconstructConfig,
    ) -> Self {
        Self {
            name: name.into(),
            positions,
            triangles,
            config: config.clone(),
            scanner_views: Vec::new(),
            target: None,
        }
    }

    /// The soup as the union of range scans seen from `views` (in the soup's coordinates): the
    /// init also turns solid what every scanner saw only through measured surface
    /// (`roar_ops::init::InitOptions::scanner_views`).
    pub fn with_scanner_views(mut self, views: Vec<ScannerView>) -> Self {
        self.scanner_views = views;
        self
    }

    /// The cleaned target T′, once prepared.
    pub fn target(&self) -> Option<&Target> {
        self.target.as_ref()
    }

    fn prepared(&self) -> Result<&Target, ShapeError> {
        self.target.as_ref().ok_or_else(|| {
            ShapeError::Loss(LossError::InvalidTarget(
                "the soup was used before `prepare`".into(),
            ))
        })
    }
}

impl Shape for SoupShape<'_> {
    fn name(&self) -> &str {
        &self.name
    }

    fn target_surface(&self) -> Option<(&[DVec3], &[[u32; 3]])> {
        let target = self.target.as_ref()?;
        Some((&target.positions, &target.triangles))
    }

    /// Builds T′ with the configured clean-up rig (`views_per_axis`, `render_resolution`,
    /// `twin_ratio`); its target renders are rendered again only if `cameras` is another rig.
    fn prepare(&mut self, cameras: &[Camera]) -> Result<(), ShapeError> {
        let mut target = build_target(
            self.positions,
            self.triangles,
            &target_options(&self.config),
        )?;
        if target.cameras != cameras {
            target.renders = render_views(&target.positions, &target.triangles, cameras, true)?;
            target.cameras = cameras.to_vec();
        }
        self.target = Some(target);
        Ok(())
    }

    /// The normalization of T′ (identity before [`Shape::prepare`]).
    fn normalization(&self) -> Normalization {
        self.target
            .as_ref()
            .map_or(Normalization::IDENTITY, |t| t.normalization)
    }

    fn initial_mesh(&self) -> Result<InitialMesh, ShapeError> {
        let target = self.prepared()?;
        let options = InitialMeshOptions {
            init: InitOptions {
                resolution: self.config.init.init_resolution,
                enclosure_winding_threshold: (self.config.init.enclosure_winding_threshold > 0.0)
                    .then_some(self.config.init.enclosure_winding_threshold),
                enclosure_max_cap_fraction: self.config.init.enclosure_max_cap_fraction,
                enclosure_max_cap_width: self.config.init.enclosure_max_cap_width,
                scanner_views: self
                    .scanner_views
                    .iter()
                    .map(|view| ScannerView {
                        toward_scanner: view.toward_scanner,
                        positions: view
                            .positions
                            .iter()
                            .map(|&p| target.normalization.apply(p))
                            .collect(),
                        triangles: view.triangles.clone(),
                    })
                    .collect(),
                target_pieces: pieces_to_aim_for(self.config.faces),
                max_pieces: most_pieces(self.config.faces),
                ..InitOptions::default()
            },
            max_faces: self.config.init.init_max_faces,
            ..InitialMeshOptions::default()
        };
        let (mesh, stats) =
            roar_ops::init::initial_mesh(&target.positions, &target.triangles, &options)
                .map_err(|e| ShapeError::Init(e.to_string()))?;
        Ok(InitialMesh {
            mesh,
            raw_faces: stats.init_faces,
            enclosure: EnclosureFigures {
                voxels_filled: stats.init.voxels_filled_by_winding,
                left_open: stats.init.enclosures_left_open,
                patches: stats.init.winding_patches,
                patches_flipped: stats.init.winding_patches_flipped,
            },
            merged: PieceMerge {
                pieces_before: stats.init.pieces_before_merge,
                radius_voxels: stats.init.merge_radius,
                pieces_dropped: stats.init.pieces_over_limit,
            },
        })
    }

    fn point_cloud(&self, initial: &Mesh) -> Result<PointCloud, ShapeError> {
        let target = self.prepared()?;
        let config = &self.config;
        let diagonal =
            Aabb::from_points(target.positions.iter().copied()).map_or(0.0, |b| b.diagonal());
        let sheet_offset = config.target.sheet_offset * diagonal;
        let mut cloud = point_cloud(
            target,
            &PointCloudOptions {
                samples: config.target.point_cloud_samples,
                winding_threshold: config.target.winding_threshold,
                sheet_offset,
                seed: config.seed,
                ..PointCloudOptions::default()
            },
        )?;
        if config.target.sharp_edge_samples > 0 {
            let (positions, triangles) = initial.to_triangles();
            let sharp = sharp_edge_samples(
                &target.bvh(),
                &two_sided_faces(&target.triangles),
                &positions,
                &triangles,
                &SharpEdgeOptions {
                    samples: config.target.sharp_edge_samples,
                    sheet_offset,
                    seed: config.seed,
                    ..SharpEdgeOptions::default()
                },
            )?;
            cloud.extend(sharp);
        }
        if cloud.points.is_empty() {
            return Err(ShapeError::Loss(LossError::InvalidTarget(
                "no target sample survived the winding-number filter".into(),
            )));
        }
        Ok(cloud)
    }

    fn target_renders(&self, cameras: &[Camera]) -> Result<Cow<'_, [Image]>, ShapeError> {
        let target = self.prepared()?;
        if target.cameras == cameras {
            Ok(Cow::Borrowed(&target.renders))
        } else {
            Ok(Cow::Owned(render_views(
                &target.positions,
                &target.triangles,
                cameras,
                true,
            )?))
        }
    }

    fn summary(&self) -> ShapeSummary {
        self.target
            .as_ref()
            .map_or_else(ShapeSummary::default, |t| ShapeSummary {
                target_faces: t.triangles.len(),
                twins_dropped: t.stats.twins_dropped,
            })
    }
}
