//! The options of the inits ([`InitOptions`], [`SdfInitOptions`]) and their measured defaults.

use super::sight::ScannerView;

/// Options of [`watertight_init`](super::watertight_init). Lengths are in voxels.
#[derive(Clone, Debug, PartialEq)]
pub struct InitOptions {
    /// Voxels along the longest bounding-box axis (default 128, `roar init`'s; the pipeline
    /// uses 192). The authors run Manifold at octree "resolution 10000", about 100 voxels per
    /// axis on a compact shape (`docs/method.md#decision-voxel-init-instead-of-manifold`).
    pub resolution: usize,
    /// Empty voxels added on each side of the bounding box (at least 2).
    pub padding: usize,
    /// Dilate the touched voxels by one voxel before the flood fill, so cracks and holes about one
    /// voxel wide do not let the exterior in.
    pub close_gaps: bool,
    /// After the flood fill, let the exterior grow back one voxel into untouched voxels (keeps the
    /// surface tight; gaps stay closed). Only used with `close_gaps`.
    pub tighten: bool,
    /// Rounds of "move toward the closest target point, then relax".
    pub projection_rounds: usize,
    /// Largest move toward the target per round.
    pub projection_step: f64,
    /// Largest total displacement of a vertex from its voxel corner.
    pub max_displacement: f64,
    /// Smallest distance kept between opposite-facing sides (see module `project`).
    pub min_gap: f64,
    /// Weight of the tangential Laplacian relaxation between projection rounds (0 = none).
    pub relax_weight: f64,
    /// Fold guard: a move is rejected if an incident triangle's unit normal has a dot product
    /// below this with its voxel square's outward normal (0.2: turned more than about 78°).
    pub min_normal_dot: f64,
    /// Fold guard: a move is rejected if two edge-adjacent triangles around the vertex get unit
    /// normals with a dot product below this (-0.5: dihedral fold beyond 120°).
    pub min_dihedral_dot: f64,
    /// Pieces with less than this fraction of the total area are dropped (default 0.1 %).
    pub min_piece_area_fraction: f64,
    /// Safety cap on the passes of the manifold repair.
    pub max_repair_passes: usize,
    /// Exterior voxels whose centre has a generalized winding number (of the soup) above this
    /// turn solid, so punctures of closed surfaces close while real tunnels stay (module
    /// `winding_solid`, which says how it was measured). Default [`ENCLOSURE_WINDING_THRESHOLD`];
    /// `None` keeps the flood fill alone. Must be at least ½, so that one flat open sheet
    /// (|w| < ½) never fills. Not the point-cloud filter's `winding_threshold`.
    pub enclosure_winding_threshold: Option<f64>,
    /// A region the enclosure rule fills is kept only if its widest cap (the largest connected
    /// patch of its boundary that no input surface covers) is at most this fraction of its whole
    /// boundary, so open containers (a tub, a head open at the neck) and the concave side of an
    /// open sheet (a leaf) do not fill. Default
    /// [`ENCLOSURE_MAX_CAP_FRACTION`]; 1 accepts every region. In `[0, 1]`.
    pub enclosure_max_cap_fraction: f64,
    /// ... and only if no point of its caps is farther than this fraction of the bounding box's
    /// longest side from the input's shell (a cap's inradius), so holes close and wide openings
    /// (an open box, a cup) stay open. Default [`ENCLOSURE_MAX_CAP_WIDTH`]; 1 accepts every
    /// region. In `[0, 1]`.
    pub enclosure_max_cap_width: f64,
    /// The scanners a set of range scans was measured from, in the soup's coordinates: with the
    /// enclosure rule on, exterior voxels hidden from every one of them by the surface it
    /// measured turn solid too (module `sight`). Empty for soups.
    pub scanner_views: Vec<ScannerView>,
    /// The most pieces the init aims for: with more, nearby pieces are merged by closing the
    /// solid (dilating, then eroding, by a ball) with the smallest radius, up to
    /// `max_merge_radius`, that leaves at most this many; pieces too far apart to merge stay.
    /// `usize::MAX` (the default) never merges.
    pub target_pieces: usize,
    /// Largest radius, in voxels, of the closing that merges pieces for `target_pieces`.
    pub max_merge_radius: usize,
    /// The most pieces the result may have: beyond it the smallest are dropped (after any
    /// merging). `usize::MAX` (the default) drops none. At least 1.
    pub max_pieces: usize,
}

impl Default for InitOptions {
    fn default() -> Self {
        InitOptions {
            resolution: 128,
            padding: 3,
            close_gaps: true,
            tighten: true,
            projection_rounds: 8,
            projection_step: 0.5,
            max_displacement: 1.0,
            min_gap: 0.5,
            relax_weight: 0.3,
            min_normal_dot: 0.2,
            min_dihedral_dot: -0.5,
            min_piece_area_fraction: 1e-3,
            max_repair_passes: 64,
            enclosure_winding_threshold: Some(ENCLOSURE_WINDING_THRESHOLD),
            enclosure_max_cap_fraction: ENCLOSURE_MAX_CAP_FRACTION,
            enclosure_max_cap_width: ENCLOSURE_MAX_CAP_WIDTH,
            scanner_views: Vec::new(),
            target_pieces: usize::MAX,
            max_merge_radius: MAX_MERGE_RADIUS,
            max_pieces: usize::MAX,
        }
    }
}

/// The default of [`InitOptions::max_merge_radius`].
pub const MAX_MERGE_RADIUS: usize = 32;

/// The default of [`InitOptions::enclosure_winding_threshold`]: ½, the level set of the
/// generalized winding number that separates inside from outside (Jacobson et al. 2013).
pub const ENCLOSURE_WINDING_THRESHOLD: f64 = 0.5;

/// The default of [`InitOptions::enclosure_max_cap_fraction`], measured on the wild meshes'
/// punctures and open containers (docs/method.md#punctures-close-while-tunnels-and-openings-stay).
pub const ENCLOSURE_MAX_CAP_FRACTION: f64 = 0.02;

/// The default of [`InitOptions::enclosure_max_cap_width`], measured with
/// `scripts/punctured.py` (docs/method.md#punctures-close-while-tunnels-and-openings-stay).
pub const ENCLOSURE_MAX_CAP_WIDTH: f64 = 0.25;

/// Options of [`sdf_init`](super::sdf_init) (supplementary §3: a 64³ grid over the bounding cube).
#[derive(Clone, Debug, PartialEq)]
pub struct SdfInitOptions {
    /// Cells along the longest axis of the bounds (supplementary §3: 64).
    pub resolution: usize,
    /// Pieces with less than this fraction of the total area are dropped (default 0.1 %).
    pub min_piece_area_fraction: f64,
    /// Safety cap on the passes of the manifold repair.
    pub max_repair_passes: usize,
}

impl Default for SdfInitOptions {
    fn default() -> Self {
        SdfInitOptions {
            resolution: 64,
            min_piece_area_fraction: 1e-3,
            max_repair_passes: 64,
        }
    }
}
