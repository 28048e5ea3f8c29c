//! The pipeline's initial mesh: the watertight init, then QEM to at most 20k faces, as the authors
//! simplify Manifold's output (`docs/method.md#watertight-init`).

use super::error::InitError;
use super::options::InitOptions;
use super::output::{InitStats, WatertightInit};
use super::watertight::watertight_init;
use crate::decimate::{DecimateOptions, DecimateStats, decimate_in_parallel, minimum_faces};
use glam::DVec3;
use roar_mesh::Mesh;
use std::time::Instant;

/// Options of [`initial_mesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct InitialMeshOptions {
    /// Options of the watertight init (step 1).
    pub init: InitOptions,
    /// Largest face count of the result (20k in the pipeline, the authors'
    /// configuration's `init_num_faces`).
    pub max_faces: usize,
    /// Options of the QEM decimation (step 2); `best_effort` is always switched on, so reaching
    /// fewer faces than asked never fails.
    pub decimate: DecimateOptions,
}

impl Default for InitialMeshOptions {
    fn default() -> Self {
        InitialMeshOptions {
            init: InitOptions::default(),
            max_faces: 20_000,
            decimate: DecimateOptions::default(),
        }
    }
}

/// What [`initial_mesh`] did and how long each stage took.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialMeshStats {
    /// Statistics of the watertight init.
    pub init: InitStats,
    /// Faces of the watertight init.
    pub init_faces: usize,
    /// Statistics of the decimation (`None` when the init already had ≤ `max_faces` faces).
    pub decimate: Option<DecimateStats>,
    /// Faces of the result.
    pub final_faces: usize,
    /// Wall time of the watertight init (seconds).
    pub init_seconds: f64,
    /// Wall time of building the half-edge mesh (seconds).
    pub build_seconds: f64,
    /// Wall time of the decimation (seconds).
    pub decimate_seconds: f64,
}

/// Builds the initial mesh of a triangle soup: [`watertight_init`], then QEM decimation
/// ([`decimate_in_parallel`], every veto on) to at most `max_faces` faces when the init has more.
///
/// Promises: a valid closed, oriented 2-manifold [`Mesh`]; the decimation target is the largest
/// even count ≤ `max_faces` (raised to the minimum the components and genera allow); when the
/// vetoes stop the decimation above the target, the closest mesh is returned and
/// `stats.final_faces` says how many faces it has.
pub fn initial_mesh(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &InitialMeshOptions,
) -> Result<(Mesh, InitialMeshStats), InitError> {
    check_max_faces(options)?;
    let start = Instant::now();
    let init = watertight_init(positions, triangles, &options.init)?;
    let init_seconds = start.elapsed().as_secs_f64();
    initial_mesh_from_init(init, init_seconds, options)
}

/// The second half of [`initial_mesh`], for callers that already hold the watertight init (e.g.
/// to inspect the voxel surface before decimation): builds the half-edge mesh and decimates it to
/// at most `options.max_faces` faces (`options.init` is not used). `init_seconds` is reported in
/// the stats as the init's wall time. Same promises as [`initial_mesh`].
pub fn initial_mesh_from_init(
    init: WatertightInit,
    init_seconds: f64,
    options: &InitialMeshOptions,
) -> Result<(Mesh, InitialMeshStats), InitError> {
    check_max_faces(options)?;
    let init_faces = init.triangles.len();

    let start = Instant::now();
    let mut mesh = Mesh::from_triangles(init.positions, &init.triangles)
        .map_err(|e| InitError::Internal(format!("the init is not a closed manifold: {e}")))?;
    let build_seconds = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let mut decimate_stats = None;
    if mesh.n_faces() > options.max_faces {
        let target = (options.max_faces & !1).max(minimum_faces(&mesh));
        let decimate_options = DecimateOptions {
            best_effort: true,
            ..options.decimate.clone()
        };
        let stats = decimate_in_parallel(&mut mesh, target, &decimate_options)
            .map_err(|e| InitError::Internal(format!("decimation failed: {e}")))?;
        decimate_stats = Some(stats);
    }
    let decimate_seconds = start.elapsed().as_secs_f64();
    let final_faces = mesh.n_faces();
    Ok((
        mesh,
        InitialMeshStats {
            init: init.stats,
            init_faces,
            decimate: decimate_stats,
            final_faces,
            init_seconds,
            build_seconds,
            decimate_seconds,
        },
    ))
}

/// `max_faces` must allow at least a tetrahedron.
fn check_max_faces(options: &InitialMeshOptions) -> Result<(), InitError> {
    if options.max_faces < 4 {
        return Err(InitError::InvalidOptions(
            "max_faces must be at least 4 (a tetrahedron)".into(),
        ));
    }
    Ok(())
}
