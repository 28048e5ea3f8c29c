//! The watertight init of a triangle soup ([`watertight_init`], [`watertight_init_with`]): the
//! steps of the module doc of `init`, from voxelization to the pieces.

use super::error::InitError;
use super::grid::{Grid, SOLID};
use super::options::InitOptions;
use super::output::{InitStats, WatertightInit};
use super::soup::{soup_bounds, split_long_edges, valid_triangles};
use super::{merge, pieces, project, solid, surface, voxelize, winding_solid};
use glam::DVec3;
use roar_mesh::spatial::TriangleBvh;

/// Builds the watertight initial mesh of a triangle soup, projecting onto the soup itself with a
/// [`TriangleBvh`] over the input. See the module doc for the steps and guarantees.
pub fn watertight_init(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &InitOptions,
) -> Result<WatertightInit, InitError> {
    let soup = valid_triangles(positions, triangles)?;
    let (min, max) = soup_bounds(&soup);
    let voxel = (max - min).max_element() / options.resolution.max(1) as f64;
    let (split_positions, split_triangles) = split_long_edges(&soup, 4.0 * voxel);
    let bvh = TriangleBvh::build(&split_positions, &split_triangles);
    let nearest = |p: DVec3, bound: f64| {
        bvh.closest_point_certified(p, bound)
            .map(|c| project::Nearest {
                point: c.closest.point,
                face: c.closest.face,
                others: c.others_squared.sqrt(),
            })
    };
    let on_face = |p: DVec3, f: u32| bvh.closest_point_on_face(p, f).point;
    let target = project::Target {
        nearest: &nearest,
        on_face: Some(&on_face),
    };
    watertight_init_from(&soup, triangles.len(), options, &target)
}

/// Like [`watertight_init`], but the projection step moves the surface toward `closest(p)`, the
/// closest point of the target to `p` (e.g. a BVH over the cleaned target; `None` = leave `p`).
pub fn watertight_init_with(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &InitOptions,
    closest: &(dyn Fn(DVec3) -> Option<DVec3> + Sync),
) -> Result<WatertightInit, InitError> {
    let soup = valid_triangles(positions, triangles)?;
    let unbounded = |p: DVec3, _bound: f64| {
        closest(p).map(|point| project::Nearest {
            point,
            face: 0,
            others: 0.0,
        })
    };
    let target = project::Target {
        nearest: &unbounded,
        on_face: None,
    };
    watertight_init_from(&soup, triangles.len(), options, &target)
}

fn check_options(options: &InitOptions) -> Result<(), InitError> {
    let bad = |what: &str| Err(InitError::InvalidOptions(what.to_string()));
    if options.resolution < 2 || options.resolution > 2048 {
        return bad("resolution must be in 2..=2048");
    }
    if options.padding < 2 {
        return bad("padding must be at least 2");
    }
    let lengths = [
        options.projection_step,
        options.max_displacement,
        options.min_gap,
        options.relax_weight,
        options.min_piece_area_fraction,
    ];
    if lengths.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return bad(
            "step, displacement, gap, relax weight and area fraction must be finite and ≥ 0",
        );
    }
    if let Some(t) = options.enclosure_winding_threshold
        && !(t.is_finite() && t >= 0.5)
    {
        return bad("enclosure_winding_threshold must be finite and at least 0.5");
    }
    if !(0.0..=1.0).contains(&options.enclosure_max_cap_fraction)
        || !(0.0..=1.0).contains(&options.enclosure_max_cap_width)
    {
        return bad("enclosure_max_cap_fraction and enclosure_max_cap_width must be in [0, 1]");
    }
    if options.target_pieces == 0 || options.max_pieces == 0 {
        return bad("target_pieces and max_pieces must be at least 1");
    }
    Ok(())
}

fn watertight_init_from(
    soup: &[[DVec3; 3]],
    input_triangles: usize,
    options: &InitOptions,
    target: &project::Target,
) -> Result<WatertightInit, InitError> {
    check_options(options)?;
    let (min, max) = soup_bounds(soup);
    if (max - min).max_element() <= 0.0 {
        return Err(InitError::ZeroExtent);
    }
    let grid = Grid::around(min, max, options.resolution, options.padding);
    let marked = voxelize::mark_surface_voxels(&grid, soup);
    let mut enclosed = winding_solid::EnclosedFill::default();
    let mut fill_enclosed = |state: &mut Vec<u8>| {
        if let Some(threshold) = options.enclosure_winding_threshold {
            enclosed = winding_solid::fill_enclosed(
                &grid,
                state,
                soup,
                threshold,
                winding_solid::CapLimits {
                    fraction: options.enclosure_max_cap_fraction,
                    inradius: options.enclosure_max_cap_width * options.resolution as f64,
                },
                &options.scanner_views,
            );
        }
    };
    let mut state = if options.close_gaps {
        let blocked = voxelize::dilate_box(&grid, &marked);
        let mut state = solid::flood_exterior(&grid, &blocked);
        fill_enclosed(&mut state);
        if options.tighten {
            solid::regrow_exterior(&grid, &state, &marked)
        } else {
            state
        }
    } else {
        let mut state = solid::flood_exterior(&grid, &marked);
        fill_enclosed(&mut state);
        state
    };
    let merged = if options.target_pieces < usize::MAX {
        merge::merge_pieces(
            &grid,
            &mut state,
            options.target_pieces,
            options.max_merge_radius,
            options.min_piece_area_fraction,
        )
    } else {
        merge::Merge::default()
    };
    let repair = solid::repair_nonmanifold(&grid, &mut state, options.max_repair_passes).ok_or(
        InitError::RepairDidNotConverge {
            passes: options.max_repair_passes,
        },
    )?;
    let mut surface = surface::extract_boundary(&grid, &state);
    let params = project::ProjectParams {
        rounds: options.projection_rounds,
        step: options.projection_step,
        max_displacement: options.max_displacement,
        min_gap: options.min_gap,
        relax_weight: options.relax_weight,
        min_normal_dot: options.min_normal_dot,
        min_dihedral_dot: options.min_dihedral_dot,
    };
    let projection = project::project_surface(&grid, &state, &mut surface, target, &params);
    let pieces = pieces::keep_large_pieces(
        &surface.positions,
        &surface.triangles,
        options.min_piece_area_fraction,
        options.max_pieces,
    );
    if pieces.triangles.is_empty() {
        return Err(InitError::EmptyResult);
    }
    let stats = InitStats {
        resolution: options.resolution,
        voxel_size: grid.voxel_size,
        grid_dims: grid.dims,
        degenerate_triangles: input_triangles - soup.len(),
        surface_voxels: marked.iter().filter(|&&m| m == 1).count(),
        solid_voxels: state.iter().filter(|&&s| s == SOLID).count(),
        nonmanifold_edges_resolved: repair.edges,
        nonmanifold_vertices_resolved: repair.vertices,
        voxels_added_for_manifoldness: repair.voxels_added,
        voxels_filled_by_winding: enclosed.filled,
        voxels_hidden_from_scanners: enclosed.hidden,
        enclosures_left_open: enclosed.left_open,
        winding_patches: enclosed.orientation.patches,
        winding_patches_flipped: enclosed.orientation.flipped,
        rejected_moves: projection.rejected_moves,
        mean_distance_to_target: projection.mean_distance,
        max_distance_to_target: projection.max_distance,
        pieces: pieces.kept,
        dropped_pieces: pieces.dropped,
        dropped_area: pieces.dropped_area,
        pieces_before_merge: merged.pieces_before,
        merge_radius: merged.radius,
        pieces_over_limit: pieces.over_limit,
    };
    Ok(WatertightInit {
        positions: pieces.positions,
        triangles: pieces.triangles,
        stats,
    })
}
