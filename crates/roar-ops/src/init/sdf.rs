//! The init of a signed distance function ([`sdf_init`]): its negative cells, repaired and
//! extracted like the watertight init's voxels.

use super::error::InitError;
use super::grid::{Grid, SOLID};
use super::options::SdfInitOptions;
use super::output::{InitStats, WatertightInit};
use super::{pieces, solid, surface};
use glam::DVec3;
use roar_mesh::spatial::Sdf;

/// Builds a closed, outward-oriented 2-manifold from the cells of a grid over
/// `[bounds_min, bounds_max]` whose centre has `sdf < 0` (supplementary §3), with the same manifold repair
/// and boundary extraction as [`watertight_init`](super::watertight_init). Interior voids are filled (the exterior is the
/// region connected to the border). Vertices stay on the grid corners. The cell centres are
/// evaluated in one batch of values ([`Sdf::values`]; no gradients); a NaN counts as outside.
pub fn sdf_init(
    sdf: &dyn Sdf,
    bounds_min: DVec3,
    bounds_max: DVec3,
    options: &SdfInitOptions,
) -> Result<WatertightInit, InitError> {
    if !bounds_min.is_finite() || !bounds_max.is_finite() {
        return Err(InitError::InvalidOptions("bounds must be finite".into()));
    }
    if (bounds_max - bounds_min).min_element() <= 0.0 {
        return Err(InitError::ZeroExtent);
    }
    if options.resolution < 2 || options.resolution > 1024 {
        return Err(InitError::InvalidOptions(
            "resolution must be in 2..=1024".into(),
        ));
    }
    let padding = 2;
    let grid = Grid::around(bounds_min, bounds_max, options.resolution, padding);
    let interior: Vec<usize> = (0..grid.len())
        .filter(|&idx| {
            let c = grid.coords(idx);
            (0..3).all(|a| c[a] >= padding && c[a] + padding < grid.dims[a])
        })
        .collect();
    let centers: Vec<DVec3> = interior
        .iter()
        .map(|&idx| grid.centre(grid.coords(idx)))
        .collect();
    let mut values = vec![0.0; centers.len()];
    sdf.values(&centers, &mut values);
    let mut inside = vec![0u8; grid.len()];
    for (&idx, &f) in interior.iter().zip(&values) {
        inside[idx] = u8::from(f < 0.0);
    }
    let mut state = solid::flood_exterior(&grid, &inside);
    let repair = solid::repair_nonmanifold(&grid, &mut state, options.max_repair_passes).ok_or(
        InitError::RepairDidNotConverge {
            passes: options.max_repair_passes,
        },
    )?;
    let surface = surface::extract_boundary(&grid, &state);
    let pieces = pieces::keep_large_pieces(
        &surface.positions,
        &surface.triangles,
        options.min_piece_area_fraction,
        usize::MAX,
    );
    if pieces.triangles.is_empty() {
        return Err(InitError::EmptyResult);
    }
    let stats = InitStats {
        resolution: options.resolution,
        voxel_size: grid.voxel_size,
        grid_dims: grid.dims,
        solid_voxels: state.iter().filter(|&&s| s == SOLID).count(),
        nonmanifold_edges_resolved: repair.edges,
        nonmanifold_vertices_resolved: repair.vertices,
        voxels_added_for_manifoldness: repair.voxels_added,
        pieces: pieces.kept,
        dropped_pieces: pieces.dropped,
        dropped_area: pieces.dropped_area,
        ..InitStats::default()
    };
    Ok(WatertightInit {
        positions: pieces.positions,
        triangles: pieces.triangles,
        stats,
    })
}
