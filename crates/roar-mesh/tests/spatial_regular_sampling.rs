//! Behaviour of the regular (MESH-style) face supersampling.

use glam::DVec3;
use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roar_mesh::spatial::regular_sampling::{continuous_grid_size, round_grid_size};
use roar_mesh::spatial::{RegularSamples, RegularSamplingOptions, face_grid, regular_samples};

/// A few triangles of very different sizes inside a unit-ish box (bbox diagonal fixed by the
/// first, large triangle).
fn mixed_mesh() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(0.01, 0.0, 0.0),
        DVec3::new(0.0, 0.01, 0.0),
        DVec3::new(0.0, 0.0, 0.02),
        DVec3::new(0.03, 0.0, 0.02),
    ];
    let triangles = vec![
        [0, 1, 2], // large: clipped to max_n
        [0, 3, 1], // large, other orientation
        [0, 4, 5], // tiny: n' ≈ 2.6 → min_n
        [6, 4, 7], // small: stochastic rounding
    ];
    (positions, triangles)
}

fn sample(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &RegularSamplingOptions,
    seed: u64,
) -> RegularSamples {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    regular_samples(positions, triangles, None, options, &mut rng).unwrap()
}

fn face_normal(positions: &[DVec3], t: [u32; 3]) -> DVec3 {
    let [a, b, c] = t.map(|v| positions[v as usize]);
    (b - a).cross(c - a)
}

#[test]
fn counts_are_n_n_plus_one_over_two_points_and_n_minus_one_squared_sub_triangles() {
    let (p, t) = mixed_mesh();
    let s = sample(&p, &t, &RegularSamplingOptions::default(), 1);
    assert_eq!(s.face_n.len(), t.len());
    assert_eq!(s.face_offsets.len(), t.len() + 1);
    for f in 0..t.len() {
        let n = s.face_n[f] as usize;
        assert_eq!(s.face_samples(f).len(), n * (n + 1) / 2);
        assert_eq!(s.face_sub_triangles(f).len(), (n - 1) * (n - 1));
        assert!(s.faces[s.face_samples(f)].iter().all(|&g| g as usize == f));
        assert!(
            s.sub_triangle_faces[s.face_sub_triangles(f)]
                .iter()
                .all(|&g| g as usize == f)
        );
        for st in &s.sub_triangles[s.face_sub_triangles(f)] {
            assert!(
                st.iter()
                    .all(|&i| s.face_samples(f).contains(&(i as usize)))
            );
        }
    }
    let total = *s.face_offsets.last().unwrap() as usize;
    assert_eq!(s.points.len(), total);
    assert_eq!(s.normals.len(), total);
    assert_eq!(s.barycentrics.len(), total);
}

#[test]
fn cap_and_minimum_are_respected() {
    let (p, t) = mixed_mesh();
    for seed in 0..20 {
        let s = sample(&p, &t, &RegularSamplingOptions::default(), seed);
        assert_eq!(s.face_n[0], 16, "clipped face rounds up to the cap");
        assert_eq!(s.face_n[1], 16);
        assert_eq!(s.face_n[2], 3, "tiny face gets the minimum grid");
        assert!((3..=16).contains(&s.face_n[3]));
    }
    let options = RegularSamplingOptions {
        max_n: 28,
        ..Default::default()
    };
    let s = sample(&p, &t, &options, 0);
    assert_eq!(s.face_n[0], 28);
    assert_eq!(
        s.face_samples(0).len(),
        406,
        "the supplementary's 420 samples: n ≤ 28"
    );
}

#[test]
fn barycentrics_sum_to_one_and_reproduce_the_points() {
    let (p, t) = mixed_mesh();
    let s = sample(&p, &t, &RegularSamplingOptions::default(), 2);
    for i in 0..s.points.len() {
        let w = s.barycentrics[i];
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(w.iter().all(|&x| (-1e-12..=1.0 + 1e-12).contains(&x)));
        let tri = t[s.faces[i] as usize].map(|v| p[v as usize]);
        let q = w[0] * tri[0] + w[1] * tri[1] + w[2] * tri[2];
        assert!((q - s.points[i]).length() < 1e-12);
    }
}

#[test]
fn sub_triangles_keep_orientation_and_tile_the_face() {
    let (p, t) = mixed_mesh();
    let s = sample(&p, &t, &RegularSamplingOptions::default(), 3);
    for (f, &tri) in t.iter().enumerate() {
        let n = face_normal(&p, tri);
        let mut area = 0.0;
        for st in &s.sub_triangles[s.face_sub_triangles(f)] {
            let [a, b, c] = st.map(|i| s.points[i as usize]);
            let sn = (b - a).cross(c - a);
            assert!(sn.dot(n) > 0.0, "sub-triangle flipped in face {f}");
            area += 0.5 * sn.length();
        }
        let face_area = 0.5 * n.length();
        assert!(
            (area - face_area).abs() < 1e-12 * face_area.max(1.0),
            "face {f}"
        );
    }
}

#[test]
fn face_grid_matches_the_spec_layout() {
    for n in 2..=16u32 {
        let (bary, sub) = face_grid(n);
        assert_eq!(bary.len(), (n * (n + 1) / 2) as usize);
        assert_eq!(sub.len(), ((n - 1) * (n - 1)) as usize);
        let step = 1.0 / (n - 1) as f64;
        for b in 0..n {
            for a in 0..n - b {
                let s = a + b;
                let w = bary[(s * (s + 1) / 2 + a) as usize];
                assert_eq!(w[1], a as f64 * step);
                assert_eq!(w[2], b as f64 * step);
            }
        }
        // Every grid edge interior to the face is shared by exactly two sub-triangles.
        let mut edges = std::collections::HashMap::new();
        for st in &sub {
            for k in 0..3 {
                let (u, v) = (st[k], st[(k + 1) % 3]);
                *edges.entry((u.min(v), u.max(v))).or_insert(0) += 1;
            }
        }
        let boundary = edges.values().filter(|&&c| c == 1).count();
        assert_eq!(boundary as u32, 3 * (n - 1));
        assert!(edges.values().all(|&c| c == 1 || c == 2));
    }
}

#[test]
fn normals_are_the_face_normal_or_the_normalized_vertex_blend() {
    let (p, t) = mixed_mesh();
    let s = sample(&p, &t, &RegularSamplingOptions::default(), 4);
    for i in 0..s.points.len() {
        let expected = face_normal(&p, t[s.faces[i] as usize]).normalize();
        assert!((s.normals[i] - expected).length() < 1e-12);
    }
    // Vertex normals pointing radially from the origin-ish: blends are unit and interpolate.
    let vertex_normals: Vec<DVec3> = p
        .iter()
        .map(|&x| (x + DVec3::new(0.1, 0.2, 0.3)).normalize())
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let s = regular_samples(
        &p,
        &t,
        Some(&vertex_normals),
        &RegularSamplingOptions::default(),
        &mut rng,
    )
    .unwrap();
    for i in 0..s.points.len() {
        let tri = t[s.faces[i] as usize];
        let w = s.barycentrics[i];
        let blend = (0..3)
            .map(|k| w[k] * vertex_normals[tri[k] as usize])
            .sum::<DVec3>()
            .normalize();
        assert!((s.normals[i] - blend).length() < 1e-12);
        assert!((s.normals[i].length() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn same_seed_gives_identical_samples_and_other_seeds_differ() {
    // Many small faces whose grid sizes need stochastic rounding.
    let mut p = Vec::new();
    let mut t = Vec::new();
    for i in 0..50 {
        let base = p.len() as u32;
        let x = i as f64 * 0.01;
        p.extend([
            DVec3::new(x, 0.0, 0.0),
            DVec3::new(x + 0.02, 0.0, 0.0),
            DVec3::new(x, 0.02, 0.0),
        ]);
        t.push([base, base + 1, base + 2]);
    }
    // D ≈ 0.51, so n' ≈ 3.5 for every face: rounding is random.
    let options = RegularSamplingOptions {
        density: 0.01,
        ..Default::default()
    };
    let a = sample(&p, &t, &options, 9);
    assert!(a.face_n.iter().all(|&n| n == 3 || n == 4), "{:?}", a.face_n);
    let b = sample(&p, &t, &options, 9);
    assert_eq!(a, b);
    let c = sample(&p, &t, &options, 10);
    assert_ne!(a.face_n, c.face_n);
}

#[test]
fn empty_mesh_gives_no_samples() {
    let s = sample(&[], &[], &RegularSamplingOptions::default(), 0);
    assert!(s.points.is_empty());
    assert_eq!(s.face_offsets, vec![0]);
}

#[test]
fn out_of_range_index_is_refused() {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let result = regular_samples(
        &[DVec3::ZERO, DVec3::X, DVec3::Y],
        &[[0, 1, 3]],
        None,
        &RegularSamplingOptions::default(),
        &mut rng,
    );
    assert!(result.is_err());
}

#[test]
fn degenerate_and_non_finite_faces_get_the_minimum_grid() {
    let p = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(f64::NAN, 0.0, 0.0),
    ];
    let s = sample(
        &p,
        &[[0, 1, 2], [0, 1, 3]],
        &RegularSamplingOptions::default(),
        0,
    );
    assert_eq!(s.face_n, vec![3, 3]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Over many seeds, the mean sample count matches N* = n'(n'+1)/2 (unclipped, n' ≥ 3).
    #[test]
    fn stochastic_rounding_is_unbiased(n_cont in 3.0f64..14.99) {
        let target = n_cont * (n_cont + 1.0) / 2.0;
        let mut rng = ChaCha8Rng::seed_from_u64(n_cont.to_bits());
        let trials = 4000;
        let mut total = 0.0;
        for _ in 0..trials {
            let n = round_grid_size(n_cont, 3, 16, &mut rng) as f64;
            prop_assert!(n == n_cont.floor() || n == n_cont.floor() + 1.0);
            total += n * (n + 1.0) / 2.0;
        }
        let mean = total / trials as f64;
        prop_assert!((mean - target).abs() < 0.03 * target, "mean {} target {}", mean, target);
    }
}

#[test]
fn sample_count_tracks_area_over_density_squared() {
    // One face of area A in a mesh of diagonal D: n'(n'+1)/2 = A / (D δ)².
    let d = 1.0;
    let density = 0.05;
    let doubled_area = 0.1;
    let n = continuous_grid_size(doubled_area, d, density);
    let expected = 0.5 * doubled_area / (d * density).powi(2);
    assert!((n * (n + 1.0) / 2.0 - expected).abs() < 1e-9);
}

#[test]
fn samples_of_an_inscribed_face_project_onto_the_reference_sphere() {
    use roar_mesh::spatial::{Projector, SphereProjector};
    // A face with its corners on the unit sphere; vertex normals radial.
    let p = vec![
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
    ];
    let normals = p.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let options = RegularSamplingOptions {
        density: 0.1,
        ..Default::default()
    };
    let s = regular_samples(&p, &[[0, 1, 2]], Some(&normals), &options, &mut rng).unwrap();
    let sphere = SphereProjector {
        center: DVec3::ZERO,
        radius: 1.0,
    };
    let projected = sphere.project(&p, &[[0, 1, 2]], &s.points, &s.normals);
    assert_eq!(projected.len(), s.points.len());
    for (i, q) in projected.iter().enumerate() {
        let q = q.expect("every sample of an inscribed face hits the sphere");
        assert!((q.length() - 1.0).abs() < 1e-12);
        // Moves outward (samples lie inside the sphere) along the sample normal.
        assert!((q - s.points[i]).dot(s.normals[i]) >= -1e-12);
        assert!((q - s.points[i]).cross(s.normals[i]).length() < 1e-12);
    }
}

/// Per-face grids written one after another from [`face_grid`], the direct reading of the layout
/// (face normals only).
fn sequential_reference(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    face_n: &[u32],
) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<u32>) {
    let (mut points, mut subs, mut sub_faces) = (Vec::new(), Vec::new(), Vec::new());
    for (f, t) in triangles.iter().enumerate() {
        let (bary, sub) = face_grid(face_n[f]);
        let offset = points.len() as u32;
        let c = t.map(|v| positions[v as usize]);
        points.extend(bary.iter().map(|w| w[0] * c[0] + w[1] * c[1] + w[2] * c[2]));
        subs.extend(sub.iter().map(|s| s.map(|i| i + offset)));
        sub_faces.extend(std::iter::repeat_n(f as u32, sub.len()));
    }
    (points, subs, sub_faces)
}

#[test]
fn parallel_fill_matches_the_sequential_layout_whatever_the_thread_count() {
    // 5120 faces: several parallel fill chunks with varied stochastic grid sizes.
    let mesh = roar_mesh::shapes::icosphere(4);
    let positions = mesh.positions().to_vec();
    let triangles: Vec<[u32; 3]> = mesh
        .faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
        .collect();
    let options = RegularSamplingOptions {
        density: 0.004,
        ..Default::default()
    };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| sample(&positions, &triangles, &options, 3))
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    let sizes: std::collections::BTreeSet<u32> = one.face_n.iter().copied().collect();
    assert!(
        sizes.len() >= 2,
        "stochastic rounding gives several sizes: {sizes:?}"
    );
    let (points, subs, sub_faces) = sequential_reference(&positions, &triangles, &one.face_n);
    assert_eq!(one.points, points);
    assert_eq!(one.sub_triangles, subs);
    assert_eq!(one.sub_triangle_faces, sub_faces);
    for f in 0..triangles.len() {
        assert!(
            one.faces[one.face_samples(f)]
                .iter()
                .all(|&g| g == f as u32)
        );
        assert_eq!(
            one.barycentrics[one.face_samples(f)],
            face_grid(one.face_n[f]).0[..]
        );
    }
}
