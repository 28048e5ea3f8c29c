//! The initial mesh on the shared real meshes (`$ROAR_TEST_DATA/{clean,wild}`), and QEM on it.
//!
//! One init per file serves every check (the init is the slow part):
//! - the voxel surface of [`watertight_init`] is a closed, outward-oriented 2-manifold whose
//!   vertices lie near the soup (mean distance / diag < 0.01);
//! - the pipeline's [`initial_mesh`] (the same init, decimated to ≤ 20k faces) is valid, has no
//!   self-intersecting face, positive volume and Chamfer/diag < 0.01 to the input;
//! - on the wild meshes, QEM takes that mesh to exactly 5000, 1000 and 500 faces with genus,
//!   components, validity and orientation kept and zero self-intersecting faces, or refuses with
//!   the named error; [`EXPECTED_REFUSALS`] lists the refusals and the test checks each reason.
//!
//! Each test prints a table (`--nocapture`).

mod common;

use common::{ManifoldReport, check_closed_manifold, data_dir};
use glam::DVec3;
use roar_eval::{ChamferOptions, fidelity};
use roar_io::{TriangleSoup, read_mesh};
use roar_mesh::Mesh;
use roar_mesh::spatial::TriangleBvh;
use roar_ops::decimate::{DecimateError, DecimateOptions, decimate, minimum_faces};
use roar_ops::init::{
    InitialMeshOptions, InitialMeshStats, WatertightInit, initial_mesh_from_init, watertight_init,
};
use std::fmt::Write as _;
use std::panic::AssertUnwindSafe;
use std::path::Path;
use std::sync::OnceLock;
use std::time::Instant;

/// Face budgets QEM must reach exactly on the wild inits (issue 6).
const BUDGETS: [usize; 3] = [5000, 1000, 500];

/// Why QEM may refuse a budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Refusal {
    /// [`DecimateError::TargetBelowMinimum`]: the components and genera need more faces.
    BelowMinimum,
    /// [`DecimateError::BudgetNotReached`] with the link condition (a collapse would pinch a
    /// handle) refusing most collapses of the last pass: the handles are already as coarse as
    /// their topology allows.
    HandlesTooCoarse,
}

/// The (wild mesh, budget) pairs QEM refuses, with the expected reason (checked by
/// [`decimate_and_check`]); every other pair must be reached exactly. None: the init of
/// trimesh-soup.stl (100 random triangles, the box's middle filled as a punctured surface) has
/// genus 20 and reaches 500 faces.
const EXPECTED_REFUSALS: &[(&str, usize, Refusal)] = &[];

/// Above this share of self-intersecting input faces, much of the input lies inside its own
/// solid (see [`check_initial_mesh`]).
const INTERPENETRATING_SHARE: f64 = 0.1;

/// One shared mesh with its init, computed once per test binary.
struct Case {
    /// `clean` or `wild`.
    folder: &'static str,
    name: String,
    soup: TriangleSoup,
    /// Checks of the voxel surface (before decimation).
    voxel: VoxelCheck,
    /// The pipeline's initial mesh and its stats.
    mesh: Mesh,
    stats: InitialMeshStats,
}

/// What is measured on the watertight init's voxel surface.
struct VoxelCheck {
    /// The closed-manifold report, or the first defect found.
    report: Result<ManifoldReport, String>,
    /// Mean distance output → soup over the bounding-box diagonal.
    out_to_soup: f64,
    /// Mean distance soup → output over the bounding-box diagonal (printed only: a closed surface
    /// cannot follow interior parts of a soup).
    soup_to_out: f64,
}

fn mean_distance(bvh: &TriangleBvh, points: &[DVec3]) -> f64 {
    points
        .iter()
        .map(|p| bvh.closest_point(*p).unwrap().distance_squared.sqrt())
        .sum::<f64>()
        / points.len() as f64
}

fn check_voxel_surface(soup: &TriangleSoup, init: &WatertightInit) -> VoxelCheck {
    let report = check_closed_manifold(&init.positions, &init.triangles);
    let used: Vec<DVec3> = soup
        .triangles
        .iter()
        .flatten()
        .map(|&i| soup.positions[i as usize])
        .collect();
    let (min, max) = used
        .iter()
        .fold((used[0], used[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let diag = (max - min).length();
    let soup_bvh = TriangleBvh::build(&soup.positions, &soup.triangles);
    let out_bvh = TriangleBvh::build(&init.positions, &init.triangles);
    VoxelCheck {
        report,
        out_to_soup: mean_distance(&soup_bvh, &init.positions) / diag,
        soup_to_out: mean_distance(&out_bvh, &used) / diag,
    }
}

/// Reads `folder/name`, builds its watertight init, checks the voxel surface, and finishes the
/// initial mesh from the same init (exactly what [`roar_ops::init::initial_mesh`] does).
fn build_case(dir: &Path, folder: &'static str, name: &str) -> Case {
    let path = dir.join(folder).join(name);
    let soup = read_mesh(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    let options = InitialMeshOptions::default();
    let start = Instant::now();
    let init = watertight_init(&soup.positions, &soup.triangles, &options.init)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let init_seconds = start.elapsed().as_secs_f64();
    let voxel = check_voxel_surface(&soup, &init);
    let (mesh, stats) = initial_mesh_from_init(init, init_seconds, &options)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    Case {
        folder,
        name: name.to_string(),
        soup,
        voxel,
        mesh,
        stats,
    }
}

/// Every shared mesh, clean then wild, each sorted by name; built once and shared by the tests
/// of this binary (a test that needs them waits while another builds them).
fn shared_cases(dir: &Path) -> &'static [Case] {
    static CASES: OnceLock<Vec<Case>> = OnceLock::new();
    CASES.get_or_init(|| {
        let mut cases = Vec::new();
        for folder in ["clean", "wild"] {
            let mut names: Vec<String> = std::fs::read_dir(dir.join(folder))
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            names.sort();
            for name in names {
                cases.push(build_case(dir, folder, &name));
            }
        }
        cases
    })
}

/// Checks the voxel surface and the initial mesh of `case`; returns its table row.
fn check_initial_mesh(case: &Case) -> String {
    let name = &case.name;
    let voxel = &case.voxel;
    let report = voxel
        .report
        .as_ref()
        .unwrap_or_else(|e| panic!("{name}: voxel surface: {e}"));
    assert!(
        voxel.out_to_soup < 0.01,
        "{name}: voxel surface → soup {}",
        voxel.out_to_soup
    );
    let (mesh, stats) = (&case.mesh, &case.stats);
    let options = InitialMeshOptions::default();
    mesh.validate()
        .unwrap_or_else(|e| panic!("{name}: invalid mesh: {e}"));
    assert!(
        mesh.n_faces() <= options.max_faces,
        "{name}: {} faces",
        mesh.n_faces()
    );
    assert_eq!(mesh.n_faces(), stats.final_faces);
    let volume = mesh.signed_volume();
    assert!(volume > 0.0, "{name}: volume {volume}");
    let crossing = roar_mesh::spatial::count_intersecting_faces(mesh);
    assert_eq!(crossing, 0, "{name}: {crossing} self-intersecting faces");
    let (positions, triangles) = mesh.to_triangles();
    let chamfer_options = ChamferOptions {
        // 20k samples a side put the sampling floor near 0.002 of the diagonal (manifoldplus-bed
        // measured 0.0103 at 20k and 0.0083 at 100k): measure with 100k so the 0.01 bound judges
        // the surface, not the sampling.
        samples: 100_000,
        seed: 7,
    };
    let soup = &case.soup;
    let f = fidelity(
        &positions,
        &triangles,
        &soup.positions,
        &soup.triangles,
        &chamfer_options,
    )
    .expect("both surfaces have area");
    // A closed surface can only follow the outside of a soup. Inputs whose parts interpenetrate
    // heavily (or that carry interior grid faces, like libigl-cube_40k) have much of their area
    // inside the union, which no closed surface can follow: the symmetric Chamfer then stays
    // large (cube_40k 0.044, trimesh-cycloidal 0.019) however good the outer surface is. Such
    // inputs are recognised by their own share of self-intersecting faces and get a looser bound.
    let (welded_positions, welded_triangles) =
        roar_eval::weld_bit_identical(&soup.positions, &soup.triangles);
    let crossing_share = roar_eval::self_intersections(
        &welded_positions,
        &welded_triangles,
        &roar_eval::SelfIntersectionOptions::default(),
    )
    .fraction;
    let limit = if crossing_share > INTERPENETRATING_SHARE {
        0.05
    } else {
        0.01
    };
    assert!(
        f.chamfer_l2_over_diag < limit,
        "{name}: chamfer/diag {} ({:.0} % of its faces self-intersect)",
        f.chamfer_l2_over_diag,
        100.0 * crossing_share
    );
    format!(
        "{:<5} {name:<34} {:>6.2}s (init {:>5.2}s, decimate {:>5.2}s) voxel {:>7} faces, {:>3} pieces (dropped {:>3}), χ={:>4}, out→soup {:.5}, soup→out {:.5} -> {:>6} faces, chamfer/diag {:.5}",
        case.folder,
        stats.init_seconds + stats.build_seconds + stats.decimate_seconds,
        stats.init_seconds,
        stats.decimate_seconds,
        stats.init_faces,
        stats.init.pieces,
        stats.init.dropped_pieces,
        report.euler,
        voxel.out_to_soup,
        voxel.soup_to_out,
        stats.final_faces,
        f.chamfer_l2_over_diag
    )
}

/// What QEM did with one budget.
enum Outcome {
    /// Reached exactly, all checks passed, in this many seconds (decimation only).
    Reached(f64),
    /// The initial mesh has no more faces than the budget: `decimate` is a no-op (checked).
    AlreadyBelow,
    /// Refused for a reason checked to be genuine; the face count where the mesh was left (the
    /// minimum possible for `BelowMinimum`).
    Refused(Refusal, usize),
}

/// Checks every promise of `decimate` on the decimated copy `m` of `init`, whose sorted
/// component genera were `genera`: valid, genera kept, no self-intersecting face, outward.
fn check_decimated(name: &str, budget: usize, m: &Mesh, genera: &[usize]) {
    m.validate()
        .unwrap_or_else(|e| panic!("{name} @ {budget}: invalid: {e}"));
    let mut after = m.component_genera();
    after.sort_unstable();
    assert_eq!(
        after, genera,
        "{name} @ {budget}: components/genera changed"
    );
    let crossing = roar_mesh::spatial::count_intersecting_faces(m);
    assert_eq!(
        crossing, 0,
        "{name} @ {budget}: {crossing} self-intersecting faces"
    );
    assert!(
        m.signed_volume() > 0.0,
        "{name} @ {budget}: orientation lost"
    );
}

/// Decimates a copy of `init` to `budget` with the default options (not best effort) and checks
/// every promise of `decimate` (a budget at or above the mesh's face count must be a no-op),
/// or that a refusal has a genuine reason: `TargetBelowMinimum`
/// names this mesh's own minimum (above the budget) and leaves it unchanged; `BudgetNotReached`
/// leaves a valid, intersection-free mesh above the budget, blocked mostly by the link
/// condition. Any other outcome fails the test.
fn decimate_and_check(name: &str, init: &Mesh, budget: usize) -> Outcome {
    let mut m = init.clone();
    let mut genera = init.component_genera();
    genera.sort_unstable();
    let start = Instant::now();
    let result = decimate(&mut m, budget, &DecimateOptions::default());
    let seconds = start.elapsed().as_secs_f64();
    match result {
        Ok(stats) if init.n_faces() <= budget => {
            assert!(stats.noop, "{name} @ {budget}: decimation never adds faces");
            assert_eq!(&m, init, "{name}: a no-op must leave the mesh unchanged");
            Outcome::AlreadyBelow
        }
        Ok(stats) => {
            assert!(stats.reached_target && !stats.noop, "{name} @ {budget}");
            assert_eq!(m.n_faces(), budget, "{name}");
            check_decimated(name, budget, &m, &genera);
            Outcome::Reached(seconds)
        }
        Err(DecimateError::TargetBelowMinimum {
            target,
            minimum,
            components,
            genus,
        }) => {
            assert_eq!(target, budget);
            assert_eq!(minimum, minimum_faces(init), "{name}");
            assert!(
                minimum > budget,
                "{name}: refused {budget} ≥ minimum {minimum}"
            );
            assert_eq!(components, genera.len(), "{name}");
            assert_eq!(genus, genera.iter().sum::<usize>(), "{name}");
            assert_eq!(&m, init, "{name}: a refusal must leave the mesh unchanged");
            Outcome::Refused(Refusal::BelowMinimum, minimum)
        }
        Err(DecimateError::BudgetNotReached {
            target,
            reached,
            reasons,
        }) => {
            assert_eq!(target, budget);
            assert!(reached > budget && reached < init.n_faces(), "{name}");
            assert_eq!(m.n_faces(), reached, "{name}: left at the closest mesh");
            check_decimated(name, budget, &m, &genera);
            assert!(
                2 * reasons.topology > reasons.total(),
                "{name} @ {budget}: stopped at {reached}, but not mostly by the link condition ({reasons})"
            );
            Outcome::Refused(Refusal::HandlesTooCoarse, reached)
        }
        Err(e) => panic!("{name}: decimation to {budget} faces failed: {e}"),
    }
}

/// Runs every budget on `case`, checks the refusals against [`EXPECTED_REFUSALS`]; returns the
/// table row.
fn check_budgets(case: &Case) -> String {
    let name = &case.name;
    let mut row = format!(
        "{name:<34} {:>7} {:>6} {:>3} {:>3}",
        case.stats.init_faces,
        case.mesh.n_faces(),
        case.mesh.components().0,
        case.mesh.genus()
    );
    for budget in BUDGETS {
        let expected = EXPECTED_REFUSALS
            .iter()
            .find(|(n, b, _)| n == name && *b == budget)
            .map(|e| e.2);
        match (decimate_and_check(name, &case.mesh, budget), expected) {
            (Outcome::Reached(s), None) => write!(row, "  ok {s:>6.2}s").unwrap(),
            (Outcome::AlreadyBelow, None) => write!(row, "  n/a (fewer)").unwrap(),
            (Outcome::Refused(why, faces), Some(expected)) if why == expected => {
                write!(row, "  {why:?} ({faces})").unwrap();
            }
            (Outcome::Reached(_) | Outcome::AlreadyBelow, Some(expected)) => {
                panic!("{name}: expected {expected:?} at {budget}, but it was reached")
            }
            (Outcome::Refused(why, faces), _) => panic!(
                "{name}: {budget} faces refused ({why:?}, {faces} faces); expected {expected:?} (EXPECTED_REFUSALS)"
            ),
        }
    }
    row
}

const QEM_HEADER: &str = "mesh                                 voxelF  initF  cc   g   per budget 5000, 1000, 500: outcome, decimation time";

/// The init checks and the budget checks on three small wild meshes (the default test run).
#[test]
fn small_meshes_give_closed_intersection_free_meshes_that_decimate_to_exact_budgets() {
    let Some(dir) = data_dir() else { return };
    for name in [
        "gc-moebius.obj",
        "gc-hourglass_ico.obj",
        "cgal-non_manifold_face_graph.off",
    ] {
        let case = build_case(&dir, "wild", name);
        println!("{}", check_initial_mesh(&case));
        println!("{}", check_budgets(&case));
    }
}

/// Every shared mesh; slow in the dev profile, run in release:
/// `cargo test --release -p roar-ops --test init_initial_mesh -- --ignored --nocapture`.
#[test]
#[ignore]
fn every_shared_mesh_gives_a_closed_intersection_free_mesh_near_the_input() {
    let Some(dir) = data_dir() else { return };
    let start = Instant::now();
    let mut table = String::new();
    for case in shared_cases(&dir) {
        writeln!(table, "{}", check_initial_mesh(case)).unwrap();
    }
    println!("{table}initial meshes checked in {:.1?}", start.elapsed());
}

/// QEM on the init of every wild mesh: exact budgets or the listed, genuine refusals. Run with
/// `cargo test --release -p roar-ops --test init_initial_mesh -- --ignored --nocapture`.
#[test]
#[ignore]
fn wild_inits_decimate_to_exact_budgets_or_a_listed_refusal() {
    let Some(dir) = data_dir() else { return };
    let wild: Vec<&Case> = shared_cases(&dir)
        .iter()
        .filter(|c| c.folder == "wild")
        .collect();
    assert!(!wild.is_empty(), "no wild meshes in {}", dir.display());
    for (name, _, _) in EXPECTED_REFUSALS {
        assert!(
            wild.iter().any(|c| c.name == *name),
            "EXPECTED_REFUSALS names {name}, which is not a wild mesh"
        );
    }
    let start = Instant::now();
    let mut table = format!("{QEM_HEADER}\n");
    let mut failures = Vec::new();
    for case in wild {
        // Keep going after a failing mesh so the table shows them all.
        match std::panic::catch_unwind(AssertUnwindSafe(|| check_budgets(case))) {
            Ok(row) => writeln!(table, "{row}").unwrap(),
            Err(e) => {
                let message = e
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                writeln!(table, "{:<34} FAILED: {message}", case.name).unwrap();
                failures.push(case.name.clone());
            }
        }
    }
    println!("{table}budgets checked in {:.1?}", start.elapsed());
    assert!(failures.is_empty(), "QEM failed on {failures:?}");
}
