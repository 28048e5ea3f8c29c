//! Helpers shared by the `spatial_*` integration tests and the `spatial_timings` example:
//! locating the real test meshes and a minimal OBJ/OFF reader (vertices and faces only,
//! polygons fan-triangulated). The real reader lives in `roar-io`; this one only feeds tests.

#![allow(dead_code)]

use glam::DVec3;
use std::path::PathBuf;

/// The folder named by `ROAR_TEST_DATA`, or `None` (with a note) when it is unset and we are not
/// on CI. Panics if it is unset on CI or names a missing folder.
pub fn test_data_dir() -> Option<PathBuf> {
    match std::env::var_os("ROAR_TEST_DATA") {
        Some(dir) => {
            let dir = PathBuf::from(dir);
            assert!(
                dir.is_dir(),
                "ROAR_TEST_DATA={} is not a folder",
                dir.display()
            );
            Some(dir)
        }
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "ROAR_TEST_DATA must be set on CI"
            );
            eprintln!("note: ROAR_TEST_DATA is unset, skipping a test on real meshes");
            None
        }
    }
}

/// Reads `positions` and fan-triangulated `triangles` from an OBJ or OFF file.
pub fn read_mesh(path: &std::path::Path) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("off"))
    {
        read_off(&text)
    } else {
        read_obj(&text)
    }
}

fn fan(polygon: &[u32], triangles: &mut Vec<[u32; 3]>) {
    for k in 1..polygon.len().saturating_sub(1) {
        triangles.push([polygon[0], polygon[k], polygon[k + 1]]);
    }
}

fn read_obj(text: &str) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for line in text.lines() {
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let c: Vec<f64> = tokens.take(3).map(|t| t.parse().unwrap()).collect();
                positions.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let polygon: Vec<u32> = tokens
                    .map(|t| {
                        let i: i64 = t.split('/').next().unwrap().parse().unwrap();
                        if i < 0 {
                            (positions.len() as i64 + i) as u32
                        } else {
                            (i - 1) as u32
                        }
                    })
                    .collect();
                fan(&polygon, &mut triangles);
            }
            _ => {}
        }
    }
    (positions, triangles)
}

fn read_off(text: &str) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut lines = text
        .lines()
        .map(|l| l.split('#').next().unwrap().trim())
        .filter(|l| !l.is_empty());
    let mut header = lines
        .next()
        .unwrap()
        .trim_start_matches("OFF")
        .split_whitespace()
        .peekable();
    let counts: Vec<usize> = if header.peek().is_some() {
        header.map(|t| t.parse().unwrap()).collect()
    } else {
        lines
            .next()
            .unwrap()
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect()
    };
    let positions: Vec<DVec3> = (0..counts[0])
        .map(|_| {
            let c: Vec<f64> = lines
                .next()
                .unwrap()
                .split_whitespace()
                .take(3)
                .map(|t| t.parse().unwrap())
                .collect();
            DVec3::new(c[0], c[1], c[2])
        })
        .collect();
    let mut triangles = Vec::new();
    for _ in 0..counts[1] {
        let v: Vec<u32> = lines
            .next()
            .unwrap()
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
        fan(&v[1..=v[0] as usize], &mut triangles);
    }
    (positions, triangles)
}
