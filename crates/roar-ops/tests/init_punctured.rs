//! The init tells inside from outside despite holes (module `init::winding_solid`): closed
//! surfaces with punctures come back with their own genus, real tunnels stay, and open surfaces
//! (which enclose nothing) keep their area.

mod common;

use common::{Soup, check_closed_manifold, count_self_intersections};
use glam::DVec3;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_mesh::Mesh;
use roar_mesh::shapes::{genus_n_solid, torus};
use roar_mesh::spatial::TriangleBvh;
use roar_ops::init::{InitOptions, ScannerView, WatertightInit, watertight_init};
use std::collections::{HashMap, HashSet};

fn soup_of(mesh: &Mesh) -> Soup {
    Soup {
        positions: mesh.positions().to_vec(),
        triangles: mesh
            .faces()
            .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
            .collect(),
    }
}

/// `soup` without a random `fraction` of its faces (seeded).
fn delete_random_faces(soup: &Soup, fraction: f64, seed: u64) -> Soup {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut order: Vec<usize> = (0..soup.triangles.len()).collect();
    order.shuffle(&mut rng);
    let remove = (fraction * soup.triangles.len() as f64).round() as usize;
    without(soup, &order[..remove].iter().copied().collect())
}

/// `soup` without the faces in `gone`.
fn without(soup: &Soup, gone: &HashSet<usize>) -> Soup {
    Soup {
        positions: soup.positions.clone(),
        triangles: (0..soup.triangles.len())
            .filter(|f| !gone.contains(f))
            .map(|f| soup.triangles[f])
            .collect(),
    }
}

/// `soup` with `holes` holes of a few faces each: a random face and the faces sharing a vertex
/// with it (seeded; the holes may merge when they meet).
fn punch_small_holes(soup: &Soup, holes: usize, seed: u64) -> Soup {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut by_vertex: HashMap<u32, Vec<usize>> = HashMap::new();
    for (f, t) in soup.triangles.iter().enumerate() {
        for v in t {
            by_vertex.entry(*v).or_default().push(f);
        }
    }
    let mut gone = HashSet::new();
    for _ in 0..holes {
        let f = rng.random_range(0..soup.triangles.len());
        let v = soup.triangles[f][rng.random_range(0..3)];
        gone.extend(by_vertex[&v].iter().copied());
    }
    without(soup, &gone)
}

fn init_with(soup: &Soup, resolution: usize, threshold: Option<f64>) -> WatertightInit {
    let options = InitOptions {
        resolution,
        enclosure_winding_threshold: threshold,
        ..InitOptions::default()
    };
    watertight_init(&soup.positions, &soup.triangles, &options).unwrap()
}

/// (pieces, total genus) of a valid, intersection-free init.
fn pieces_and_genus(out: &WatertightInit) -> (usize, i64) {
    assert_eq!(
        count_self_intersections(&out.positions, &out.triangles),
        0,
        "self-intersections"
    );
    genus_of(out)
}

/// (pieces, total genus) of a closed manifold.
fn genus_of(out: &WatertightInit) -> (usize, i64) {
    let report = check_closed_manifold(&out.positions, &out.triangles).unwrap();
    let genus = (2 * report.components as i64 - report.euler) / 2;
    (report.components, genus)
}

fn default_threshold() -> Option<f64> {
    Some(roar_ops::init::ENCLOSURE_WINDING_THRESHOLD)
}

/// Voxels along the longest axis in these tests: one deleted face is a hole a few voxels wide,
/// wider than the one-voxel gap closing of the flood fill.
const RESOLUTION: usize = 96;

/// Tori (major radius 1, minor 0.35) and the genus-3 slab of `genus_n_solid`, punctured.
fn punctured_cases() -> Vec<(&'static str, Soup, i64)> {
    // Coarse enough that one deleted face is a hole wider than the gap closing.
    let coarse_torus = soup_of(&torus(32, 12, 1.0, 0.35));
    // Finer, so that a hole of a few faces is a small part of the tube's girth.
    let fine_torus = soup_of(&torus(48, 18, 1.0, 0.35));
    let genus3 = soup_of(&genus_n_solid(3));
    let fine_genus3 = subdivide(&genus3);
    vec![
        (
            "torus, 5 % of faces deleted",
            delete_random_faces(&coarse_torus, 0.05, 1),
            1,
        ),
        (
            "torus, 10 small holes",
            punch_small_holes(&fine_torus, 10, 2),
            1,
        ),
        (
            "genus 3, 5 % of faces deleted",
            delete_random_faces(&genus3, 0.05, 3),
            3,
        ),
        (
            "genus 3, 10 small holes",
            punch_small_holes(&fine_genus3, 10, 4),
            3,
        ),
    ]
}

/// Each triangle split into four at its edge midpoints (shared midpoints, so the surface stays
/// connected).
fn subdivide(soup: &Soup) -> Soup {
    let mut positions = soup.positions.clone();
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut midpoint = |a: u32, b: u32, positions: &mut Vec<DVec3>| {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
            positions.len() as u32 - 1
        })
    };
    let mut triangles = Vec::new();
    for &[a, b, c] in &soup.triangles {
        let ab = midpoint(a, b, &mut positions);
        let bc = midpoint(b, c, &mut positions);
        let ca = midpoint(c, a, &mut positions);
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    Soup {
        positions,
        triangles,
    }
}

#[test]
fn punctured_torus_and_genus_three_solid_come_back_with_their_own_genus() {
    for (name, soup, genus) in punctured_cases() {
        let shell = init_with(&soup, RESOLUTION, None);
        let out = init_with(&soup, RESOLUTION, default_threshold());
        println!(
            "{name}: {} faces, genus {} without the winding rule, {:?} with it ({} voxels filled)",
            soup.triangles.len(),
            genus_of(&shell).1,
            pieces_and_genus(&out),
            out.stats.voxels_filled_by_winding
        );
        assert_eq!(pieces_and_genus(&out), (1, genus), "{name}");
        assert!(out.stats.voxels_filled_by_winding > 0, "{name}");
    }
}

/// The flood fill alone leaves a shell with a handle per puncture: the rule above is what
/// closes them.
#[test]
fn without_the_winding_rule_the_punctures_become_handles() {
    let (name, soup, genus) = punctured_cases().swap_remove(0);
    let out = init_with(&soup, RESOLUTION, None);
    let (_, shell_genus) = genus_of(&out);
    assert!(shell_genus > genus + 2, "{name}: genus {shell_genus}");
}

#[test]
fn a_torus_whose_hole_is_as_wide_as_its_tube_keeps_its_hole() {
    // Hole diameter 2 (R − r) = tube diameter 2 r  ⇔  R = 2 r.
    let torus = soup_of(&torus(64, 24, 0.5, 0.25));
    for (name, soup) in [
        (
            "whole",
            Soup {
                positions: torus.positions.clone(),
                triangles: torus.triangles.clone(),
            },
        ),
        ("5 % of faces deleted", delete_random_faces(&torus, 0.05, 5)),
    ] {
        let out = init_with(&soup, RESOLUTION, default_threshold());
        assert_eq!(pieces_and_genus(&out), (1, 1), "{name}");
    }
}

/// Two-sided Chamfer distance between the init and the soup: mean distance from the init's
/// vertices to the soup plus mean distance from the soup's vertices to the init.
fn chamfer(out: &WatertightInit, soup: &Soup) -> f64 {
    let to_soup = TriangleBvh::build(&soup.positions, &soup.triangles);
    let to_out = TriangleBvh::build(&out.positions, &out.triangles);
    let mean = |points: &[DVec3], bvh: &TriangleBvh| {
        points
            .iter()
            .map(|p| bvh.closest_point(*p).unwrap().distance_squared.sqrt())
            .sum::<f64>()
            / points.len() as f64
    };
    mean(&out.positions, &to_soup) + mean(&soup.positions, &to_out)
}

/// A grid of `n × n` quads over `[0, 1]²`, lifted by `height(x, y)`, as an open sheet.
fn sheet(n: u32, height: impl Fn(f64, f64) -> f64) -> Soup {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            positions.push(DVec3::new(x, y, height(x, y)));
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Soup {
        positions,
        triangles,
    }
}

/// A flat disc of radius 0.5 (a fan of rings).
fn disc(rings: u32, sectors: u32) -> Soup {
    let mut positions = vec![DVec3::ZERO];
    for r in 1..=rings {
        for s in 0..sectors {
            let a = std::f64::consts::TAU * s as f64 / sectors as f64;
            let radius = 0.5 * r as f64 / rings as f64;
            positions.push(DVec3::new(radius * a.cos(), radius * a.sin(), 0.0));
        }
    }
    let ring = |r: u32, s: u32| 1 + (r - 1) * sectors + s % sectors;
    let mut triangles = Vec::new();
    for s in 0..sectors {
        triangles.push([0, ring(1, s), ring(1, s + 1)]);
    }
    for r in 1..rings {
        for s in 0..sectors {
            let (a, b, c, d) = (
                ring(r, s),
                ring(r + 1, s),
                ring(r + 1, s + 1),
                ring(r, s + 1),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    Soup {
        positions,
        triangles,
    }
}

#[test]
fn an_open_disc_and_a_one_sided_sheet_keep_their_area() {
    let cases = [
        ("open disc", disc(12, 48)),
        (
            "one-sided curved sheet",
            sheet(24, |x, y| {
                0.25 * (std::f64::consts::PI * x).sin() * (1.0 + y)
            }),
        ),
    ];
    for (name, soup) in cases {
        let shell = init_with(&soup, RESOLUTION, None);
        let out = init_with(&soup, RESOLUTION, default_threshold());
        assert_eq!(pieces_and_genus(&out), (1, 0), "{name}");
        let (before, after) = (chamfer(&shell, &soup), chamfer(&out, &soup));
        assert!(
            after <= 1.1 * before,
            "{name}: Chamfer {after} against {before} without the winding rule"
        );
        assert_eq!(out.stats.voxels_filled_by_winding, 0, "{name}");
    }
}

#[test]
fn a_threshold_below_one_half_is_refused() {
    let soup = disc(2, 8);
    let options = InitOptions {
        enclosure_winding_threshold: Some(0.4),
        ..InitOptions::default()
    };
    let err = watertight_init(&soup.positions, &soup.triangles, &options).unwrap_err();
    assert!(
        err.to_string().contains("enclosure_winding_threshold"),
        "{err}"
    );
}

#[test]
fn a_cube_scanned_from_two_opposite_sides_is_solid_only_with_the_lines_of_sight() {
    // The unit cube's top (seen from +z) and bottom (seen from −z), its sides unseen: the
    // winding number at its centre is 2 × 1/6 (two faces' solid angles), under any threshold,
    // so the winding rule leaves two thin shells; every point inside is hidden from both
    // scanners by the faces they measured, so the lines of sight make the cube solid.
    let top = sheet(16, |_, _| 1.0);
    let mut bottom = sheet(16, |_, _| 0.0);
    for t in &mut bottom.triangles {
        t.swap(1, 2);
    }
    let base = top.positions.len() as u32;
    let soup = Soup {
        positions: [top.positions.clone(), bottom.positions.clone()].concat(),
        triangles: top
            .triangles
            .iter()
            .copied()
            .chain(bottom.triangles.iter().map(|t| t.map(|v| v + base)))
            .collect(),
    };
    let view = |patch: &Soup, toward_scanner: DVec3| ScannerView {
        toward_scanner,
        positions: patch.positions.clone(),
        triangles: patch.triangles.clone(),
    };
    let options = InitOptions {
        resolution: 48,
        enclosure_winding_threshold: Some(0.6),
        enclosure_max_cap_fraction: 1.0,
        enclosure_max_cap_width: 1.0,
        ..InitOptions::default()
    };
    let volume = |out: &WatertightInit| -> f64 {
        out.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| out.positions[v as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    };
    let shells = watertight_init(&soup.positions, &soup.triangles, &options).unwrap();
    let with_sight = InitOptions {
        scanner_views: vec![view(&top, DVec3::Z), view(&bottom, -DVec3::Z)],
        ..options.clone()
    };
    let solid = watertight_init(&soup.positions, &soup.triangles, &with_sight).unwrap();
    let (pieces, genus) = pieces_and_genus(&solid);
    println!(
        "winding rule alone: {:?} pieces, volume {:.3}; with the lines of sight: {pieces} \
         piece(s), genus {genus}, volume {:.3}, {} voxels hidden",
        genus_of(&shells).0,
        volume(&shells),
        volume(&solid),
        solid.stats.voxels_hidden_from_scanners
    );
    assert!(
        volume(&shells) < 0.3,
        "the winding rule alone filled the cube"
    );
    assert_eq!((pieces, genus), (1, 0));
    assert!(volume(&solid) > 0.9, "volume {}", volume(&solid));
    // Seen from above only, with a strip of the bottom (x < 0.3) measured by nothing that
    // looks at it: the top hides the whole cube, but only the columns over the strip have
    // measured surface behind them, so the shadow elsewhere (the unseen back of a set of scans
    // taken from one side) is not claimed.
    let strip: Vec<DVec3> = bottom
        .positions
        .iter()
        .map(|p| DVec3::new(0.3 * p.x, p.y, p.z))
        .collect();
    let one_side = [top.positions.clone(), strip].concat();
    let from_above = InitOptions {
        scanner_views: vec![view(&top, DVec3::Z)],
        ..options.clone()
    };
    let out = watertight_init(&one_side, &soup.triangles, &from_above).unwrap();
    println!("seen from above only: volume {:.3}", volume(&out));
    assert!(
        volume(&out) < 0.45,
        "the shadow was claimed: volume {}",
        volume(&out)
    );
}
