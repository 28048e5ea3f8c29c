//! Chamfer, Hausdorff and normal similarity on analytic shapes; the evaluation report.

mod common;

use common::shapes::{cube, icosphere};
use glam::DVec3;
use roar_eval::{ChamferOptions, EvalError, EvalOptions, evaluate, fidelity};

fn options(samples: usize, seed: u64) -> ChamferOptions {
    ChamferOptions { samples, seed }
}

#[test]
fn chamfer_between_concentric_spheres_is_the_radius_gap() {
    let (p1, t1) = icosphere(1.0, 4);
    let (p2, t2) = icosphere(1.1, 4);
    let f = fidelity(&p2, &t2, &p1, &t1, &options(50_000, 3)).unwrap();
    assert!(
        (f.chamfer_l2 - 0.1).abs() < 0.003,
        "chamfer {}",
        f.chamfer_l2
    );
    assert!(
        (f.chamfer_l2_squared_sum - 0.02).abs() < 0.0012,
        "{}",
        f.chamfer_l2_squared_sum
    );
    assert!(
        f.hausdorff >= f.chamfer_l2 && f.hausdorff < 0.13,
        "{}",
        f.hausdorff
    );
    assert!((f.chamfer_l2_over_diag - f.chamfer_l2 / f.reference_diagonal).abs() < 1e-15);
    assert!((f.reference_diagonal - 2.0 * 3f64.sqrt()).abs() < 0.4);
    assert!(f.normal_cosine > 0.99 && f.normal_cosine_abs >= f.normal_cosine);
}

#[test]
fn inverted_winding_flips_the_signed_cosine_only() {
    let (p, t) = icosphere(1.0, 3);
    let inverted: Vec<[u32; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let f = fidelity(&p, &inverted, &p, &t, &options(20_000, 1)).unwrap();
    assert!(f.normal_cosine < -0.99, "{}", f.normal_cosine);
    assert!(f.normal_cosine_abs > 0.99);
}

#[test]
fn chamfer_of_a_mesh_with_itself_is_sampling_noise() {
    let (p, t) = icosphere(1.0, 3);
    let f = fidelity(&p, &t, &p, &t, &options(50_000, 5)).unwrap();
    // Mean spacing of 50k samples on a unit sphere is about √(4π/50k) ≈ 0.016.
    assert!(f.chamfer_l2 < 0.01, "self chamfer {}", f.chamfer_l2);
    assert!(
        f.chamfer_l2 > 0.0,
        "different seeds on each side give distinct samples"
    );
    let g = fidelity(&p, &t, &p, &t, &options(50_000, 99)).unwrap();
    assert!(
        (f.chamfer_l2 - g.chamfer_l2).abs() < 0.1 * f.chamfer_l2,
        "noise level is stable"
    );
    let h = fidelity(&p, &t, &p, &t, &options(50_000, 5)).unwrap();
    assert_eq!(f, h, "same seed, bit-identical result");
}

#[test]
fn nothing_to_sample_gives_no_fidelity() {
    let (p, t) = cube();
    let flat = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
    assert!(fidelity(&flat, &[[0, 1, 2]], &p, &t, &options(100, 0)).is_none());
    assert!(fidelity(&p, &t, &p, &[], &options(100, 0)).is_none());
}

#[test]
fn report_serializes_its_sections() {
    let (p, t) = cube();
    let opts = EvalOptions {
        chamfer: options(2_000, 0),
        self_intersections: None,
    };
    let without = evaluate(&p, &t, None, &opts).unwrap();
    let json = serde_json::to_value(&without).unwrap();
    for (section, key) in [
        ("topology", "vertices"),
        ("topology", "faces"),
        ("topology", "boundary_edges"),
        ("topology_welded", "nonmanifold_edges"),
        ("topology_welded", "nonmanifold_vertices"),
        ("topology_welded", "components"),
        ("topology_welded", "watertight"),
        ("quality", "aspect_ratio_median"),
        ("quality", "degenerate"),
        ("orientation", "signed_volume"),
    ] {
        assert!(json[section].get(key).is_some(), "missing {section}.{key}");
    }
    assert!(json.get("fidelity").is_none() && json.get("self_intersections").is_none());
    assert_eq!(json["topology_welded"]["genus"], 0);
    assert!((json["orientation"]["signed_volume"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    // Cube faces are right isosceles triangles.
    let q = json["quality"]["aspect_ratio_median"].as_f64().unwrap();
    assert!((q - (1.0 + 2f64.sqrt()) / 2.0).abs() < 1e-12);

    let with = evaluate(&p, &t, Some((&p, &t)), &opts).unwrap();
    let json = serde_json::to_value(&with).unwrap();
    for key in [
        "chamfer_l2",
        "chamfer_l2_over_diag",
        "chamfer_l2_squared_sum",
        "normal_cosine",
        "normal_cosine_abs",
        "hausdorff",
        "hausdorff_over_diag",
        "chamfer_exact",
        "chamfer_exact_over_diag",
        "hausdorff_exact_over_diag",
        "normal_cosine_exact",
        "normal_cosine_exact_abs",
    ] {
        assert!(json["fidelity"][key].is_number(), "missing fidelity.{key}");
    }

    let by_default = evaluate(&p, &t, None, &EvalOptions::default()).unwrap();
    let json = serde_json::to_value(&by_default).unwrap();
    for key in ["faces", "fraction", "faces_eps_discounted", "offset"] {
        assert!(
            json["self_intersections"][key].is_number(),
            "missing self_intersections.{key}"
        );
    }
    assert_eq!(json["self_intersections"]["faces"], 0);
}

/// An STL-like soup (every triangle with its own three vertices) of two unit cubes, the second
/// shifted by `shift`.
fn two_cube_soup(shift: DVec3) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (p, t) = cube();
    let mut sp = Vec::new();
    let mut st = Vec::new();
    for offset in [DVec3::ZERO, shift] {
        for f in &t {
            let base = sp.len() as u32;
            sp.extend(f.map(|i| p[i as usize] + offset));
            st.push([base, base + 1, base + 2]);
        }
    }
    (sp, st)
}

#[test]
fn self_intersections_are_counted_on_the_welded_soup() {
    // Without welding every pair of neighbouring triangles would touch at unshared vertices.
    let (p, t) = two_cube_soup(DVec3::splat(10.0));
    let r = evaluate(&p, &t, None, &EvalOptions::default()).unwrap();
    let s = r.self_intersections.unwrap();
    assert_eq!((s.faces, s.faces_eps_discounted), (0, 0));

    // Interpenetrating cubes: corner of the second inside the first. Three faces of each cube
    // pass through the other (each face is two triangles, both cut or touched).
    let (p, t) = two_cube_soup(DVec3::splat(0.5));
    let s = evaluate(&p, &t, None, &EvalOptions::default())
        .unwrap()
        .self_intersections
        .unwrap();
    assert!(s.faces >= 6 && s.faces <= 12, "faces {}", s.faces);
    assert_eq!(s.faces_eps_discounted, s.faces, "deep crossings survive ε");
    assert!((s.fraction - s.faces as f64 / 24.0).abs() < 1e-15);
}

#[test]
fn invalid_input_is_an_error_not_a_panic() {
    let (mut p, t) = cube();
    let opts = EvalOptions::default();
    let bad = [[0, 1, 99]];
    assert!(matches!(
        evaluate(&p, &bad, None, &opts),
        Err(EvalError::IndexOutOfRange {
            face: 0,
            index: 99,
            ..
        })
    ));
    assert!(matches!(
        evaluate(&p, &t, Some((&p, &bad)), &opts),
        Err(EvalError::IndexOutOfRange {
            mesh: "reference",
            ..
        })
    ));
    p[3].y = f64::NAN;
    assert!(matches!(
        evaluate(&p, &t, None, &opts),
        Err(EvalError::NonFinite { vertex: 3, .. })
    ));
    let empty = evaluate(&[], &[], None, &opts).unwrap();
    assert!(!empty.topology.watertight && empty.quality.aspect_ratio_median.is_none());
}
