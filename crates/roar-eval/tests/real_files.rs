//! Every shared test mesh: the welded topology figures equal those measured in `SOURCES.md`.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use roar_eval::{signed_volume, topology, weld_bit_identical};

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
        let soup = common::load(&path);
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
            ("polys", int(c("polys")), soup.polygons as i64),
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
