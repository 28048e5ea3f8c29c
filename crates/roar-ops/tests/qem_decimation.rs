//! QEM decimation: exact budgets, no new self-intersections, topology kept, clear errors.

mod common;

use proptest::prelude::*;
use roar_mesh::Mesh;
use roar_mesh::shapes::{icosphere, perturbed, torus};
use roar_ops::decimate::{
    DecimateError, DecimateOptions, decimate, decimate_in_parallel, decimate_with, minimum_faces,
};

/// Decimates a copy to `target` and checks every promise of `decimate`.
fn decimate_and_check(mesh: &Mesh, target: usize) -> Mesh {
    let mut m = mesh.clone();
    let (components, genus) = (m.components().0, m.genus());
    let stats = decimate(&mut m, target, &DecimateOptions::default())
        .unwrap_or_else(|e| panic!("decimate to {target}: {e}"));
    assert_eq!(m.n_faces(), target);
    assert!(stats.reached_target && !stats.noop);
    assert_eq!(stats.final_faces, target);
    m.validate().expect("valid after decimation");
    assert_eq!(m.components().0, components);
    assert_eq!(m.genus(), genus);
    assert_eq!(
        roar_mesh::spatial::count_intersecting_faces(&m),
        0,
        "self-intersections after decimation to {target}"
    );
    assert!(m.signed_volume() > 0.0, "orientation kept");
    m
}

#[test]
fn icosphere_reaches_exact_budgets_and_stays_on_the_sphere() {
    let sphere = icosphere(5); // 20480 faces
    for target in [5000, 1000, 500] {
        let m = decimate_and_check(&sphere, target);
        let worst = m
            .vertices()
            .map(|v| (m.position(v).length() - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 0.03,
            "vertex {worst} off the unit sphere at {target} faces"
        );
    }
}

#[test]
fn torus_reaches_exact_budgets_keeping_genus_one() {
    let t = torus(96, 48, 1.0, 0.35); // 9216 faces
    for target in [5000, 1000, 500] {
        let m = decimate_and_check(&t, target);
        assert_eq!(m.genus(), 1);
    }
}

#[test]
fn collapse_callback_sees_every_collapse_and_remap_matches() {
    let mut m = icosphere(3);
    let before = m.n_faces();
    let mut seen = 0;
    let stats = decimate_with(&mut m, 200, &DecimateOptions::default(), |c| {
        assert_ne!(c.survivor, c.removed);
        seen += 1;
    })
    .unwrap();
    assert_eq!(seen, stats.collapses);
    assert_eq!(seen, (before - 200) / 2);
    let remap = stats.remap.expect("compacted");
    assert_eq!(remap.vertices.iter().flatten().count(), m.n_vertices());
}

#[test]
fn odd_budget_is_refused_naming_the_even_neighbours() {
    let mut m = icosphere(2);
    let before = m.clone();
    let err = decimate(&mut m, 101, &DecimateOptions::default()).unwrap_err();
    assert!(matches!(
        err,
        DecimateError::OddTarget {
            below: 100,
            above: 102,
            ..
        }
    ));
    assert!(err.to_string().contains("100 or 102"), "{err}");
    assert_eq!(m, before);
}

#[test]
fn impossible_budgets_are_refused_up_front() {
    let mut sphere = icosphere(2);
    let err = decimate(&mut sphere, 2, &DecimateOptions::default()).unwrap_err();
    assert!(
        matches!(err, DecimateError::TargetBelowMinimum { minimum: 4, .. }),
        "{err}"
    );
    let mut t = torus(12, 8, 1.0, 0.4);
    assert_eq!(minimum_faces(&t), 14);
    let err = decimate(&mut t, 12, &DecimateOptions::default()).unwrap_err();
    assert!(err.to_string().contains("at least 14 faces"), "{err}");
}

#[test]
fn target_at_or_above_the_count_is_a_noop() {
    let mut m = icosphere(1);
    let before = m.clone();
    let stats = decimate(&mut m, 400, &DecimateOptions::default()).unwrap();
    assert!(stats.noop && !stats.reached_target && stats.remap.is_none());
    assert_eq!(m, before);
    let stats = decimate(&mut m, 80, &DecimateOptions::default()).unwrap();
    assert!(stats.noop && stats.reached_target);
}

#[test]
fn blocked_budget_is_a_named_error_or_the_closest_mesh_with_best_effort() {
    // A thin torus pushed to its 14-face minimum: greedy collapses with strict vetoes stop early.
    let t = torus(24, 8, 1.0, 0.1);
    let strict = DecimateOptions {
        min_normal_dot: 0.9,
        quality_bounds: vec![1.5],
        max_passes_per_bound: 2,
        ..DecimateOptions::default()
    };
    let mut m = t.clone();
    let err = decimate(&mut m, 14, &strict).unwrap_err();
    let DecimateError::BudgetNotReached {
        target,
        reached,
        reasons,
    } = &err
    else {
        panic!("expected BudgetNotReached, got {err}");
    };
    assert_eq!(*target, 14);
    assert!(*reached > 14 && *reached <= t.n_faces());
    assert!(reasons.total() > 0);
    assert_eq!(err.to_string().lines().count(), 1);
    assert!(err.to_string().contains("stopped at"), "{err}");
    m.validate().unwrap();

    let mut m = t.clone();
    let best = DecimateOptions {
        best_effort: true,
        ..strict
    };
    let stats = decimate(&mut m, 14, &best).unwrap();
    assert!(!stats.reached_target);
    assert_eq!(
        m.n_faces(),
        *reached,
        "best effort keeps the same closest mesh"
    );
    m.validate().unwrap();
    assert_eq!(roar_mesh::spatial::count_intersecting_faces(&m), 0);
}

/// A closed box of the given size cut into `cells[k]` steps along axis `k`: its six flat sides
/// are grids of rectangles, each cut into two right triangles.
fn gridded_box(cells: [usize; 3], size: [f64; 3]) -> Mesh {
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut vertex = |p: [f64; 3]| -> u32 {
        let key = p.map(|x| (x * 1e9).round() as i64);
        *index.entry(key).or_insert_with(|| {
            positions.push(glam::DVec3::from_array(p));
            positions.len() as u32 - 1
        })
    };
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0.0, 1.0] {
            for i in 0..cells[u] {
                for j in 0..cells[v] {
                    let mut corner = |a: usize, b: usize| {
                        let mut p = [0.0; 3];
                        p[axis] = side * size[axis];
                        p[u] = a as f64 / cells[u] as f64 * size[u];
                        p[v] = b as f64 / cells[v] as f64 * size[v];
                        vertex(p)
                    };
                    let q = [
                        corner(i, j),
                        corner(i + 1, j),
                        corner(i + 1, j + 1),
                        corner(i, j + 1),
                    ];
                    if side > 0.0 {
                        triangles.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
                    } else {
                        triangles.extend([[q[0], q[2], q[1]], [q[0], q[3], q[2]]]);
                    }
                }
            }
        }
    }
    Mesh::from_triangles(positions, &triangles).expect("a closed box")
}

/// Median, 95th percentile and largest aspect ratio of the faces.
fn aspect_percentiles(m: &Mesh) -> [f64; 3] {
    let mut q: Vec<f64> = m
        .faces()
        .map(|f| roar_mesh::spatial::triangle_quality(m.face_vertices(f).map(|v| m.position(v))))
        .collect();
    q.sort_by(f64::total_cmp);
    [q[q.len() / 2], q[q.len() * 95 / 100], q[q.len() - 1]]
}

#[test]
fn planar_quadrics_and_the_quality_penalty_keep_flat_regions_well_shaped() {
    // On flat sides every in-plane collapse has zero quadric error, so without the planar
    // quadrics and the penalty only the hard bound steers the layout (measured: median, 95th
    // percentile and worst aspect ratio 1.34, 6.2, 9.6; with them 1.16, 1.8, 2.7).
    let boxed = gridded_box([24; 3], [1.0, 0.6, 0.3]);
    let plain = DecimateOptions {
        quality_penalty_above: 0.0,
        planar_weight: 0.0,
        ..DecimateOptions::default()
    };
    let mut rough = boxed.clone();
    decimate(&mut rough, 300, &plain).unwrap();
    let smooth = decimate_and_check(&boxed, 300);
    let [rough_median, rough_p95, rough_max] = aspect_percentiles(&rough);
    let [median, p95, max] = aspect_percentiles(&smooth);
    assert!(
        median <= rough_median && p95 < 0.5 * rough_p95 && max < rough_max,
        "aspect median, p95, max: {median}, {p95}, {max} with the defaults, \
         {rough_median}, {rough_p95}, {rough_max} without"
    );
    // The box keeps its shape: every vertex stays on its surface, up to 1e-4 of its size (the
    // planar terms, 1e-3 of the face planes' weight, pull vertices on creases and corners
    // slightly off them: measured 2e-5 at worst).
    for v in smooth.vertices() {
        let p = smooth.position(v);
        let off = [p.x, p.y, p.z]
            .iter()
            .zip([1.0, 0.6, 0.3])
            .map(|(&x, s)| x.abs().min((x - s).abs()))
            .fold(f64::INFINITY, f64::min);
        assert!(off < 1e-4, "vertex {p} left the box's sides");
    }
}

#[test]
fn crease_planes_keep_a_thin_flap_from_being_eaten_from_its_rim() {
    // A sphere flattened 100-fold (a disk whose rim folds back onto itself), decimated 20-fold:
    // its two sides share one plane up to the thickness, so the face planes barely notice a
    // collapse that pulls the rim inward; the crease planes do.
    let (mut positions, triangles) = icosphere(4).to_triangles();
    for p in &mut positions {
        p.z *= 0.02 * p.z.abs();
    }
    let flap = Mesh::from_triangles(positions, &triangles).expect("a closed flattened sphere");
    // The flap's narrowest extent: the smallest over directions in its plane of the farthest
    // vertex along it (1 for the flap itself, up to its faceting).
    let reach = |m: &Mesh| {
        (0..360)
            .map(|k| {
                let d = glam::DVec3::new(
                    (k as f64).to_radians().cos(),
                    (k as f64).to_radians().sin(),
                    0.0,
                );
                m.vertices()
                    .map(|v| m.position(v).dot(d))
                    .fold(f64::MIN, f64::max)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let run = |crease_weight: f64| {
        let mut m = flap.clone();
        let options = DecimateOptions {
            crease_weight,
            ..DecimateOptions::default()
        };
        decimate(&mut m, 256, &options).unwrap();
        (m.surface_area() / flap.surface_area(), reach(&m))
    };
    // Measured: area kept 0.974 and reach 0.969 with the crease planes, 0.949 and 0.946 without.
    let ((area, reach), (area_without, reach_without)) = (run(1.0), run(0.0));
    assert!(
        1.0 - area < 0.7 * (1.0 - area_without) && 1.0 - reach < 0.7 * (1.0 - reach_without),
        "area and reach kept: {area}, {reach} with crease planes, \
         {area_without}, {reach_without} without"
    );
    decimate_and_check(&flap, 256);
}

/// Two concentric spheres 0.5 % of the radius apart (two components, 2 × 81 920 faces): a
/// collapse on either shell that moved a vertex by more than the gap would cross the other one.
fn nested_shells() -> Mesh {
    let (outer_p, outer_t) = icosphere(6).to_triangles();
    let (inner_p, inner_t) = icosphere(6).to_triangles();
    let offset = outer_p.len() as u32;
    let positions: Vec<_> = outer_p
        .into_iter()
        .chain(inner_p.into_iter().map(|p| 0.995 * p))
        .collect();
    let triangles: Vec<[u32; 3]> = outer_t
        .into_iter()
        .chain(inner_t.into_iter().map(|t| t.map(|v| v + offset)))
        .collect();
    Mesh::from_triangles(positions, &triangles).expect("two closed shells")
}

/// The two-thread decimation keeps every promise of `decimate` on a large mesh where the
/// intersection veto matters, and gives the same bytes on one thread and on two.
#[test]
fn parallel_decimation_keeps_the_promises_and_ignores_the_thread_count() {
    let shells = nested_shells();
    assert_eq!(roar_mesh::spatial::count_intersecting_faces(&shells), 0);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut m = shells.clone();
            let stats = decimate_in_parallel(&mut m, 2000, &DecimateOptions::default())
                .unwrap_or_else(|e| panic!("parallel decimation: {e}"));
            (m, stats)
        })
    };
    let (m, stats) = run(2);
    assert_eq!(m.n_faces(), 2000);
    assert!(stats.reached_target && stats.remap.is_none());
    assert_eq!(stats.initial_faces, shells.n_faces());
    assert_eq!(stats.collapses, (shells.n_faces() - 2000) / 2);
    m.validate().expect("valid after parallel decimation");
    assert_eq!(m.components().0, 2);
    assert_eq!(m.genus(), 0);
    assert_eq!(roar_mesh::spatial::count_intersecting_faces(&m), 0);
    assert!(m.signed_volume() > 0.0);
    let (one_thread, _) = run(1);
    assert_eq!(one_thread.to_triangles(), m.to_triangles());
}

/// Small meshes and errors behave exactly as with `decimate`.
#[test]
fn parallel_decimation_of_small_meshes_is_decimate() {
    let t = torus(40, 20, 1.0, 0.35);
    let mut a = t.clone();
    let mut b = t.clone();
    let sa = decimate(&mut a, 500, &DecimateOptions::default()).unwrap();
    let sb = decimate_in_parallel(&mut b, 500, &DecimateOptions::default()).unwrap();
    assert_eq!(sa, sb);
    assert_eq!(a, b);
    let err = decimate_in_parallel(&mut b, 101, &DecimateOptions::default()).unwrap_err();
    assert!(matches!(err, DecimateError::OddTarget { .. }));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]
    #[test]
    fn random_perturbed_shapes_stay_valid_and_never_intersect(
        seed in 0u64..1000,
        amplitude in 0.0f64..0.04,
        use_torus in any::<bool>(),
        frac in 0.05f64..0.9,
    ) {
        let base = if use_torus { torus(20, 10, 1.0, 0.4) } else { icosphere(3) };
        let mesh = perturbed(&base, amplitude, seed);
        let clean = roar_mesh::spatial::count_intersecting_faces(&mesh) == 0;
        let target = ((base.n_faces() as f64 * frac) as usize / 2 * 2).max(minimum_faces(&base));
        let mut m = mesh.clone();
        let opts = DecimateOptions { best_effort: true, ..DecimateOptions::default() };
        let stats = decimate(&mut m, target, &opts).unwrap();
        prop_assert!(m.validate().is_ok());
        prop_assert_eq!(m.genus(), base.genus());
        prop_assert!(m.n_faces() >= target);
        if clean {
            prop_assert_eq!(roar_mesh::spatial::count_intersecting_faces(&m), 0);
        }
        if stats.reached_target {
            prop_assert_eq!(m.n_faces(), target);
        }
    }
}

/// Timing of a large decimation (run with `cargo test --release -p roar-ops --test
/// qem_decimation -- --ignored --nocapture`).
#[test]
#[ignore]
fn timing_100k_to_5k() {
    let t = torus(250, 200, 1.0, 0.35); // 100 000 faces
    let start = std::time::Instant::now();
    let m = decimate_and_check(&t, 5000);
    println!(
        "torus 100k -> 5k faces: {:.2?} (incl. checks)",
        start.elapsed()
    );
    let mut m2 = t.clone();
    let start = std::time::Instant::now();
    let stats = decimate(&mut m2, 5000, &DecimateOptions::default()).unwrap();
    println!("decimate only: {:.2?}, {:?}", start.elapsed(), stats.vetoes);
    let mut m3 = t.clone();
    let opts = DecimateOptions {
        check_self_intersections: false,
        ..DecimateOptions::default()
    };
    let start = std::time::Instant::now();
    decimate(&mut m3, 5000, &opts).unwrap();
    println!(
        "decimate without intersection veto: {:.2?}",
        start.elapsed()
    );
    assert_eq!(m.n_faces(), 5000);
}

#[test]
fn strips_of_degenerate_caps_on_creases_are_collapsed_first() {
    // A strip of caps: zero-width faces whose corners lie on a crease line, as the
    // optimization leaves them. Made on a gridded box by splitting a crease edge (a, b) at m₁
    // (a third of the way) and m₂ (two thirds), nudging both by 1e-9 so the caps' normals are
    // rounding noise rather than exactly zero, and flipping the new edges (m₁, c), (m₂, c):
    //
    //   c-side faces (a, m₁, c) (m₁, m₂, c) (m₂, b, c)  ==>  (a, b, c) + caps (a, m₁, m₂) (a, m₂, b)
    //
    // The surface does not change. Removing a cap makes its neighbour in the strip part of the
    // collapse's fan, unchanged or nearly: a noisy normal that must not veto, a ratio that must
    // not be compared as if it meant something.
    let mut m = gridded_box([6, 6, 6], [1.0, 1.0, 1.0]);
    let creases: Vec<_> = m
        .edges()
        .filter(|&e| {
            let h = e.halfedge();
            m.face_normal(m.face(h))
                .dot(m.face_normal(m.face(h.twin())))
                < 0.5
        })
        .collect();
    let mut used = std::collections::HashSet::new();
    let mut strips = 0;
    for e in creases {
        let ends = m.edge_vertices(e);
        if ends.iter().any(|v| used.contains(v)) {
            continue;
        }
        used.extend(ends);
        let first = m.split_edge(e, 1.0 / 3.0);
        // The split edge keeps its id and now joins a and m₁; (m₁, b) is the first new edge.
        let second = m.split_edge(first.new_edges[0], 0.5);
        let nudge = [
            glam::DVec3::new(1e-9, -1e-9, 1e-9),
            glam::DVec3::splat(-1e-9),
        ];
        for (split, d) in [first, second].iter().zip(nudge) {
            let v = split.new_vertex;
            m.set_position(v, m.position(v) + d);
        }
        m.flip(first.new_edges[1]).expect("(m₁, c) flips");
        m.flip(second.new_edges[1]).expect("(m₂, c) flips");
        strips += 1;
    }
    assert!(strips >= 8, "{strips} strips");
    assert!(aspect_percentiles(&m)[2] > 1e6, "the caps are degenerate");
    let overlapping = roar_mesh::spatial::count_intersecting_faces(&m);
    assert!(overlapping > 0, "a strip's caps overlap each other");

    // Removing as many faces as the strips hold (each cap goes with one face across the
    // crease) leaves no cap, hence no overlap (`decimate_and_check` counts them).
    let n = m.n_faces();
    let m = decimate_and_check(&m, n - 4 * strips);
    let [_, _, worst] = aspect_percentiles(&m);
    assert!(worst < 10.0, "worst aspect ratio {worst}");
    // The box is unchanged: every vertex still lies on its surface.
    for v in m.vertices() {
        let p = m.position(v);
        let off = p.min_element().abs().min((p.max_element() - 1.0).abs());
        assert!(off < 1e-4, "vertex {p} off the box");
    }
}

#[test]
fn a_degenerate_limit_below_the_last_bound_or_not_finite_is_refused_by_name() {
    for limit in [5.0, f64::INFINITY, f64::NAN] {
        let options = DecimateOptions {
            degenerate_quality: limit,
            ..DecimateOptions::default()
        };
        let mut m = icosphere(2);
        match decimate(&mut m, 100, &options) {
            Err(DecimateError::InvalidOption { name, .. }) => {
                assert_eq!(name, "degenerate_quality")
            }
            other => panic!("limit {limit}: {other:?}"),
        }
        assert_eq!(m.n_faces(), 320, "the mesh is untouched");
    }
}

/// The bumpy sphere's signed distance (approximately: a sphere of radius 0.9 with bumps of 0.08).
fn bumpy_sphere(p: glam::DVec3) -> f64 {
    p.length() - 0.9 - 0.08 * (5.0 * p.x).sin() * (4.0 * p.y).sin() * (3.0 * p.z).cos()
}

/// A marching tetrahedra extraction of [`bumpy_sphere`]: closed, every face a cut of a grid
/// tetrahedron, many of them slivers.
fn marching_bumpy_sphere(samples: usize) -> Mesh {
    let (min, max) = (glam::DVec3::splat(-1.2), glam::DVec3::splat(1.2));
    let step = (max - min) / (samples - 1) as f64;
    let mut values = Vec::with_capacity(samples * samples * samples);
    for i in 0..samples {
        for j in 0..samples {
            for k in 0..samples {
                let p = min + glam::DVec3::new(i as f64, j as f64, k as f64) * step;
                values.push(bumpy_sphere(p) as f32);
            }
        }
    }
    let (positions, triangles) =
        roar_mesh::spatial::marching_tetrahedra(&values, [samples; 3], min, max);
    Mesh::from_triangles(positions, &triangles).expect("a closed extraction")
}

#[test]
fn a_marching_extraction_full_of_slivers_reaches_small_budgets() {
    let mesh = marching_bumpy_sphere(96);
    // No vertex leaves the surface by more than the bumps' height (0.08). (At 2000 faces the
    // farthest is 0.044: the collapses that remove slivers cost less, see
    // `DecimateOptions::degenerate_quality`.)
    for (target, tolerance) in [(2000, 0.08), (200, 0.08), (4, f64::INFINITY)] {
        let m = decimate_and_check(&mesh, target);
        let farthest = m
            .vertices()
            .map(|v| bumpy_sphere(m.position(v)).abs())
            .fold(0.0, f64::max);
        assert!(
            farthest <= tolerance,
            "{target} faces: a vertex {farthest} off the surface"
        );
    }
    // Bounded at 20, without the last step, the slivers block the budget.
    let twenty = DecimateOptions {
        quality_bounds: vec![10.0, 20.0],
        ..DecimateOptions::default()
    };
    let stalled = decimate(&mut mesh.clone(), 200, &twenty);
    assert!(
        matches!(stalled, Err(DecimateError::BudgetNotReached { .. })),
        "{stalled:?}"
    );
}
