//! The [`Shape`] seam: what the reconstruction pipeline needs from an input, whatever kind it is
//! (a triangle soup, a signed distance function, a set of range scans).
//!
//! The pipeline asks a shape, in this order:
//! 1. [`Shape::prepare`] once, with the camera rig: the place for costly set-up (a soup cleans
//!    itself up and renders its target here);
//! 2. [`Shape::normalization`]: the map from the input's coordinates into the rig's sphere;
//! 3. [`Shape::initial_mesh`]: a closed mesh M0 to start from;
//! 4. [`Shape::point_cloud`]: the oriented target samples P, given M0 (for sharp-feature samples);
//! 5. [`Shape::target_renders`]: one normal map per camera of the rig;
//! 6. [`Shape::signed_distance`] and [`Shape::projector`]: what else it offers the losses and
//!    the Face Split block.
//!
//! Every geometric quantity a shape returns (meshes, points, normals, renders) is in **rig
//! coordinates**: the input's coordinates mapped by [`Shape::normalization`], inside the sphere
//! of radius [`roar_mesh::spatial::RIG_RADIUS`] the cameras look at. The pipeline maps its output
//! back with the same normalization. Normals point **outward**, out of the solid the shape
//! bounds, and triangles are ordered counter-clockwise seen from outside.

use std::borrow::Cow;
use std::sync::Arc;

use glam::DVec3;
use roar_mesh::Mesh;
use roar_mesh::spatial::{Normalization, Projector, Sdf};
use roar_render::{Camera, Image};

use roar_loss::{LossError, PointCloud};

/// Why a shape could not give what the pipeline asked for.
#[derive(Debug, thiserror::Error)]
pub enum ShapeError {
    /// A target, a render or a sample set could not be made.
    #[error("{0}")]
    Loss(#[from] LossError),
    /// No initial mesh could be made.
    #[error("init: {0}")]
    Init(String),
    /// A field could not be sampled (a non-finite value, bad sampling options).
    #[error("{0}")]
    Field(String),
}

/// The initial closed mesh M0 of a shape, with how many faces it had before any decimation.
#[derive(Clone, Debug)]
pub struct InitialMesh {
    /// A closed, oriented 2-manifold in rig coordinates.
    pub mesh: Mesh,
    /// Faces of the shape's raw init before it was decimated (the voxel surface of a soup's
    /// watertight init; `mesh.n_faces()` when nothing was decimated). For reports.
    pub raw_faces: usize,
    /// What the enclosure rule of a soup's watertight init did (zeros for other kinds of init).
    pub enclosure: EnclosureFigures,
    /// How the init merged or dropped pieces to fit the face budget (zeros when it did not).
    pub merged: PieceMerge,
}

/// What the enclosure rule (generalized winding number) of a soup's watertight init did, for
/// reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EnclosureFigures {
    /// Voxels the rule made solid (punctures closed).
    pub voxels_filled: usize,
    /// Regions the rule left open, their cap being too wide for a puncture (an open surface's
    /// opening).
    pub left_open: usize,
    /// Patches of the soup (faces joined across two-face edges) oriented for the winding number.
    pub patches: usize,
    /// Of those, the patches turned over because their back was seen more than their front.
    pub patches_flipped: usize,
}

/// How an init brought more separate parts than the face budget can shape down to fewer pieces,
/// for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PieceMerge {
    /// Pieces before merging (0 when the init does not count them).
    pub pieces_before: usize,
    /// Radius, in voxels, of the closing that merged nearby pieces (0: none).
    pub radius_voxels: usize,
    /// Pieces dropped, smallest first, because even merged they were too many for the budget.
    pub pieces_dropped: usize,
}

/// Figures about a shape's own preparation, for reports (zeros where a kind has no such thing).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShapeSummary {
    /// Faces of the prepared target surface (a soup's cleaned T′).
    pub target_faces: usize,
    /// Inward twins a soup's clean-up dropped.
    pub twins_dropped: usize,
}

/// One kind of input, as the reconstruction pipeline sees it (module docs: order of calls,
/// coordinates and orientation).
///
/// A shape may cache anything it computes: the pipeline calls [`Shape::prepare`] once and every
/// other method but [`Shape::name`] at most once per run, so what a method costs is paid once
/// (and [`Shape::initial_mesh`] not at all when the config asks for the sphere init); the costs
/// below are those of the soup implementation.
pub trait Shape {
    /// A short name for reports and messages (e.g. the input's file name).
    fn name(&self) -> &str;

    /// Set-up before any other call, for the pipeline's camera rig (the same `cameras` are later
    /// passed to [`Shape::target_renders`]). The default does nothing. A soup welds, normalizes
    /// and cleans itself up here (renders from its own clean-up rig, then the target renders):
    /// the costliest step of a shape, seconds at the rig's 25–36 views of 512².
    fn prepare(&mut self, cameras: &[Camera]) -> Result<(), ShapeError> {
        let _ = cameras;
        Ok(())
    }

    /// The map from the input's coordinates into rig coordinates: it puts the shape's bounds
    /// into the rig's sphere ([`Normalization::fit`] does so for a vertex set). Cheap; called
    /// after [`Shape::prepare`]; the pipeline inverts it on its output.
    fn normalization(&self) -> Normalization;

    /// The initial closed, oriented 2-manifold M0 in rig coordinates, enclosing what the shape
    /// encloses (a soup: its watertight voxel init, decimated; seconds).
    fn initial_mesh(&self) -> Result<InitialMesh, ShapeError>;

    /// The oriented target point cloud P in rig coordinates (unit outward normals), including
    /// samples on sharp features; `initial` is M0, whose sharp edges a soup samples. Must not be
    /// empty. Seconds for a soup's 200k samples with their winding-number filter.
    fn point_cloud(&self, initial: &Mesh) -> Result<PointCloud, ShapeError>;

    /// One flat-shaded normal map of the shape per camera, in the order of `cameras`, as
    /// `roar_loss::render_views` makes them for a mesh (RGB the outward unit normal, alpha the
    /// coverage; culling on). Borrowed when the shape already holds them (a soup renders them in
    /// [`Shape::prepare`]); each image is `width × height` of its camera.
    fn target_renders(&self, cameras: &[Camera]) -> Result<Cow<'_, [Image]>, ShapeError>;

    /// The shape's signed distance in rig coordinates ([`Sdf`]: negative inside), if it has one
    /// (SDF inputs do; a soup does not). Shared, so a loss can keep it.
    fn signed_distance(&self) -> Option<Arc<dyn Sdf>> {
        None
    }

    /// A projector onto the shape for the Face Split block's scores, if the shape has a better
    /// one than the default k-NN planar projection over [`Shape::point_cloud`].
    fn projector(&self) -> Option<&dyn Projector> {
        None
    }

    /// The surface the target renders show (a soup's cleaned-up T′), in rig coordinates, if
    /// the shape has one: the finish fairs what lies far from it.
    fn target_surface(&self) -> Option<(&[DVec3], &[[u32; 3]])> {
        None
    }

    /// Figures about the preparation, for reports (default: zeros).
    fn summary(&self) -> ShapeSummary {
        ShapeSummary::default()
    }
}
