//! What an init produces: the mesh ([`WatertightInit`]) and what was done ([`InitStats`]).

use glam::DVec3;

/// What the initialization did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InitStats {
    /// Voxels along the longest axis of the bounds.
    pub resolution: usize,
    /// Edge length of one voxel (world units).
    pub voxel_size: f64,
    /// Grid size including padding.
    pub grid_dims: [usize; 3],
    /// Input triangles skipped as degenerate (zero area).
    pub degenerate_triangles: usize,
    /// Voxels touched by the soup (0 for the SDF init).
    pub surface_voxels: usize,
    /// Solid voxels after the manifold repair.
    pub solid_voxels: usize,
    /// Checkerboard edges (two solid voxels touching along an edge only) resolved by adding a voxel.
    pub nonmanifold_edges_resolved: usize,
    /// Grid corners whose solid or exterior octants were not face-connected, resolved by filling.
    pub nonmanifold_vertices_resolved: usize,
    /// Voxels added to the solid by the manifold repair.
    pub voxels_added_for_manifoldness: usize,
    /// Exterior voxels turned solid by the enclosure rule, by their winding number or, with
    /// [`InitOptions::scanner_views`](super::InitOptions::scanner_views), as hidden from every scanner (punctures closed; 0 for the
    /// SDF init or when the rule is off).
    pub voxels_filled_by_winding: usize,
    /// Exterior voxels hidden from every scanner of [`InitOptions::scanner_views`](super::InitOptions::scanner_views) (turned
    /// solid with the winding rule's; 0 without scanner views).
    pub voxels_hidden_from_scanners: usize,
    /// Regions the winding-number rule would have filled but left open, their cap being too wide
    /// (see [`InitOptions::enclosure_max_cap_fraction`](super::InitOptions::enclosure_max_cap_fraction)).
    pub enclosures_left_open: usize,
    /// Patches of the soup (faces joined across two-face edges) the enclosure rule oriented
    /// before taking the winding number (0 when the rule is off).
    pub winding_patches: usize,
    /// Of those, the patches turned over because their back was seen more than their front.
    pub winding_patches_flipped: usize,
    /// Projection moves rejected by the fold guard.
    pub rejected_moves: usize,
    /// Mean distance from output vertices to the target (world units; 0 for the SDF init).
    pub mean_distance_to_target: f64,
    /// Largest distance from an output vertex to the target (world units; 0 for the SDF init).
    pub max_distance_to_target: f64,
    /// Pieces in the output.
    pub pieces: usize,
    /// Pieces dropped for being under the area threshold.
    pub dropped_pieces: usize,
    /// Total area of the dropped pieces.
    pub dropped_area: f64,
    /// Pieces of the solid before merging, counted on the voxels (26-connected, over the area
    /// threshold); 0 when [`InitOptions::target_pieces`](super::InitOptions::target_pieces) is off.
    pub pieces_before_merge: usize,
    /// Radius in voxels of the closing that merged pieces (0: none).
    pub merge_radius: usize,
    /// Pieces dropped, smallest first, to stay within [`InitOptions::max_pieces`](super::InitOptions::max_pieces).
    pub pieces_over_limit: usize,
}

/// A closed, outward-oriented, 2-manifold triangle mesh and how it was made.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WatertightInit {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Statistics.
    pub stats: InitStats,
}
