//! Every shared test mesh: the welded topology figures equal those measured in `SOURCES.md`.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use roar_eval::{
    SelfIntersectionOptions, self_intersections, signed_volume, topology, weld_bit_identical,
};

/// One row of a "Measured characteristics" table, by column name.
struct Row {
    folder: &'static str,
    file: String,
    cells: BTreeMap<String, String>,
}

fn parse_sources(text: &str) -> Vec<Row> {
    let mut rows = Vec::new();
    let mut folder = None;
    let mut in_table = false;
    let mut header: Vec<String> = Vec::new();
    for line in text.lines() {
        if line.starts_with("## clean/") {
            folder = Some("clean");
        } else if line.starts_with("## wild/") {
            folder = Some("wild");
        }
        if line.starts_with("### ") {
            in_table = line.contains("Measured characteristics");
            header.clear();
            continue;
        }
        if !in_table || !line.starts_with('|') {
            continue;
        }
        let cells: Vec<String> = line
            .trim_matches('|')
            .split('|')
            .map(|c| c.trim().to_string())
            .collect();
        if header.is_empty() {
            header = cells;
        } else if cells[0].starts_with('`') {
            rows.push(Row {
                folder: folder.expect("table outside a folder section"),
                file: cells[0].trim_matches('`').to_string(),
                cells: header.iter().cloned().zip(cells).collect(),
            });
        }
    }
    rows
}

fn int(s: &str) -> i64 {
    s.replace(',', "")
        .parse()
        .unwrap_or_else(|_| panic!("not an integer: {s}"))
}

#[test]
fn welded_topology_matches_sources_md() {
    let Some(root) = common::test_data() else {
        return;
    };
    let sources = std::fs::read_to_string(root.join("SOURCES.md")).expect("SOURCES.md");
    let rows = parse_sources(&sources);
    assert_eq!(rows.len(), 44, "expected 14 clean + 30 wild rows");
    let mut mismatches = Vec::new();
    for row in &rows {
        let path = root.join(row.folder).join(&row.file);
        assert!(Path::new(&path).is_file(), "missing {}", path.display());
        let soup = roar_io::read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        let raw = topology(&soup.positions, &soup.triangles);
        let (wp, wt) = weld_bit_identical(&soup.positions, &soup.triangles);
        let t = topology(&wp, &wt);
        // The measurement loaded a multi-solid ASCII STL through trimesh as a scene of one mesh per
        // solid, which merged each solid's vertices: its V and bndR are then the welded figures.
        let merged_per_solid = row.file.to_lowercase().ends_with(".stl")
            && std::fs::read(&path)
                .unwrap()
                .windows(6)
                .filter(|w| w == b"solid ")
                .count()
                > 1;
        let (stored_v, raw_bnd) = if merged_per_solid {
            (wp.len(), t.boundary_edges)
        } else {
            (soup.positions.len(), raw.boundary_edges)
        };
        let c = |k: &str| {
            row.cells
                .get(k)
                .unwrap_or_else(|| panic!("no column {k}"))
                .as_str()
        };
        let (bnd, loops) = match c("bnd (loops)").split_once(' ') {
            Some((b, l)) => (int(b), int(l.trim_matches(|ch| ch == '(' || ch == ')'))),
            None => (int(c("bnd (loops)")), 0),
        };
        let (dup_s, dup_o) = c("dupS/dupO").split_once('/').unwrap();
        let checks: [(&str, i64, i64); 16] = [
            ("V", int(c("V")), stored_v as i64),
            ("F", int(c("F")), soup.triangles.len() as i64),
            ("polys", int(c("polys")), soup.n_polygons as i64),
            ("Vw", int(c("Vw")), wp.len() as i64),
            ("bndR", int(c("bndR")), raw_bnd as i64),
            ("cc", int(c("cc")), t.components as i64),
            ("wt", (c("wt") == "yes") as i64, t.watertight as i64),
            ("bnd", bnd, t.boundary_edges as i64),
            ("loops", loops, t.boundary_loops as i64),
            ("nmE", int(c("nmE")), t.nonmanifold_edges as i64),
            ("nmV", int(c("nmV")), t.nonmanifold_vertices as i64),
            ("dupS", int(dup_s), t.duplicate_faces_same as i64),
            ("dupO", int(dup_o), t.duplicate_faces_opposite as i64),
            ("deg", int(c("deg")), t.degenerate_faces as i64),
            ("flip", int(c("flip")), t.inconsistent_edges as i64),
            ("χ", int(c("χ")), t.euler_characteristic),
        ];
        for (name, want, got) in checks {
            if want != got {
                mismatches.push(format!("{}: {name} want {want} got {got}", row.file));
            }
        }
        let want_vol: f64 = c("vol").parse().unwrap();
        let got_vol = signed_volume(&soup.positions, &soup.triangles);
        let tol = 1e-3 * want_vol.abs().max(1e-12);
        if (got_vol - want_vol).abs() > tol {
            mismatches.push(format!("{}: vol want {want_vol} got {got_vol}", row.file));
        }
    }
    assert!(
        mismatches.is_empty(),
        "{} mismatches:\n{}",
        mismatches.len(),
        mismatches.join("\n")
    );
}

/// Files where MeshLab's `selfX` and our exact count differ by more than the tolerance, with our
/// count (exact arithmetic, deterministic, so pinned). Measured differences and their causes:
/// MeshLab (vcg `TestFaceFaceIntersection`) skips pairs sharing two vertices (faces folded onto
/// each other across an edge, e.g. at non-manifold edges), tests pairs sharing one vertex only
/// with a floating-point segment through the two edge midpoints (missing coplanar overlaps), and
/// decides contacts in floating point, so exact touches (a corner on a face, coplanar faces
/// meeting along an edge) are found for some files and missed for others. Faces that intersect
/// with the triangles shrunk by 1e-6 toward their centroids ("proper" crossings, plus duplicates,
/// without pairs sharing a vertex) are given after "proper" for comparison.
const SELF_X_EXCEPTIONS: [(&str, usize); 12] = [
    ("trimesh-cycloidal.ply", 23_364), // selfX 17,433; proper 21,625
    ("trimesh-box.STL", 2_320),        // selfX 653; proper 1,565 (touching bodies)
    ("trimesh-featuretype.STL", 896),  // selfX 825; proper 0: only touches at cracks
    ("trimesh-angle_block.STL", 111),  // selfX 77; proper 0, 48 with a shared vertex
    ("trimesh-not_convex.obj", 60),    // selfX 0; 12 non-manifold edges with folded faces
    ("manifoldplus-bathtub.obj", 30),  // selfX 4; proper 2, 29 with a shared vertex
    ("manifoldplus-bed.obj", 658),     // selfX 375; proper 402
    ("manifoldplus-chair.off", 1_520), // selfX 538; proper 1,463 (duplicates, touches)
    ("manifoldplus-table.off", 418),   // selfX 219; proper 379
    ("manifold-input.obj", 57_652),    // selfX 53,508; proper 57,652 (coplanar twins)
    ("c3d-beetle.obj", 71),            // selfX 64; proper 40, 71 with a shared vertex
    ("luke-cruiser.obj", 332),         // selfX 284; proper 332
];

/// Self-intersecting faces agree with `SOURCES.md`'s `selfX` (MeshLab on the welded mesh).
///
/// Rule: `|ours − selfX| ≤ max(5, 2 % of selfX)`. The slack of 5 covers overlaps beyond a shared
/// vertex that exact arithmetic finds and MeshLab's midpoint test misses (horse: 5 against 3,
/// dragon and camelhead likewise agree only with them counted); 2 % covers floating-point
/// decisions on touching contacts in large soups (trimesh-chair_model: 12,756 against 12,752).
/// Files beyond it are listed in [`SELF_X_EXCEPTIONS`] with the reason: there our count must
/// be at least MeshLab's (we never miss what it finds) and equal the pinned exact figure.
/// Only files up to `max_faces` faces are checked (the full set is an ignored test).
fn check_self_intersections(max_faces: usize) {
    let Some(root) = common::test_data() else {
        return;
    };
    let sources = std::fs::read_to_string(root.join("SOURCES.md")).expect("SOURCES.md");
    let mut failures = Vec::new();
    let mut checked = 0;
    for row in parse_sources(&sources) {
        if int(&row.cells["F"]) as usize > max_faces {
            continue;
        }
        checked += 1;
        let soup = roar_io::read_mesh(&root.join(row.folder).join(&row.file))
            .unwrap_or_else(|e| panic!("{e}"));
        let (wp, wt) = weld_bit_identical(&soup.positions, &soup.triangles);
        let s = self_intersections(&wp, &wt, &SelfIntersectionOptions::default());
        let want = int(&row.cells["selfX"]) as usize;
        assert!(s.faces_eps_discounted <= s.faces);
        let ok = match SELF_X_EXCEPTIONS.iter().find(|e| e.0 == row.file) {
            Some(&(_, pinned)) => s.faces == pinned && s.faces >= want,
            None => s.faces.abs_diff(want) as f64 <= (0.02 * want as f64).max(5.0),
        };
        if !ok {
            failures.push(format!("{}: selfX {want}, ours {}", row.file, s.faces));
        }
    }
    assert!(checked > 0, "no file checked");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn self_intersections_match_sources_md_on_small_files() {
    check_self_intersections(25_000);
}

#[test]
#[ignore = "slow in debug (about a minute): every file, up to 100k faces; run in release"]
fn self_intersections_match_sources_md_on_every_file() {
    check_self_intersections(usize::MAX);
}
