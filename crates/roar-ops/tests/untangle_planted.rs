//! Untangle clears planted crossings; the step limiter never lets a step create one.

use roar_mesh::shapes::{icosphere, torus};
use roar_mesh::spatial::intersecting_pairs;
use roar_mesh::{DVec3, Mesh};
use roar_ops::untangle::{LimiterOptions, UntangleOptions, limit_steps, untangle};

fn pairs(mesh: &Mesh) -> usize {
    let (p, t) = mesh.to_triangles();
    intersecting_pairs(&p, &t).len()
}

/// Two unit icospheres whose centres are 1.5 apart, in one mesh (two crossing components).
fn two_spheres(level: u32) -> Mesh {
    let s = icosphere(level);
    let (p, t) = s.to_triangles();
    let n = p.len() as u32;
    let mut positions = p.clone();
    positions.extend(p.iter().map(|&x| x + DVec3::new(1.5, 0.0, 0.0)));
    let mut triangles = t.clone();
    triangles.extend(t.iter().map(|f| f.map(|i| i + n)));
    Mesh::from_triangles(positions, &triangles).unwrap()
}

/// A sphere flattened to a thick disc with a patch of its top pushed through its bottom.
fn dented_disc(level: u32) -> Mesh {
    let mut m = icosphere(level);
    for v in m.vertices().collect::<Vec<_>>() {
        let p = m.position(v);
        let mut q = DVec3::new(p.x, p.y, 0.3 * p.z);
        if p.z > 0.0 && p.x * p.x + p.y * p.y < 0.3 * 0.3 {
            q.z = -0.45;
        }
        m.set_position(v, q);
    }
    m
}

fn check_untangled(mut m: Mesh, label: &str) {
    let before = pairs(&m);
    assert!(before > 0, "{label}: the planted case must cross");
    let start = std::time::Instant::now();
    let stats = untangle(&mut m, &UntangleOptions::default());
    println!(
        "{label}: {before} pairs, {stats:?} in {:.2?}",
        start.elapsed()
    );
    assert_eq!(stats.initial_pairs, before);
    assert!(stats.unresolved_faces.is_empty(), "{label}: {stats:?}");
    assert_eq!(pairs(&m), 0, "{label}: still intersecting");
    m.validate().unwrap();
    assert!(stats.rounds > 0 && stats.moves > 0);
}

#[test]
fn two_interpenetrating_spheres_are_separated() {
    let m = two_spheres(3);
    assert_eq!(m.components().0, 2);
    check_untangled(m, "two spheres");
}

#[test]
fn patch_pushed_through_the_opposite_wall_is_pulled_back() {
    check_untangled(dented_disc(3), "dented disc");
}

#[test]
fn mesh_without_intersections_is_left_exactly_unchanged() {
    let mut m = torus(30, 12, 1.0, 0.3);
    let before = m.clone();
    let stats = untangle(&mut m, &UntangleOptions::default());
    assert_eq!(m, before);
    assert_eq!((stats.rounds, stats.moves, stats.initial_pairs), (0, 0, 0));
}

#[test]
fn separated_spheres_keep_the_margin() {
    let mut m = two_spheres(2);
    untangle(
        &mut m,
        &UntangleOptions {
            margin_rel: 1e-3,
            ..UntangleOptions::default()
        },
    );
    // Offsetting every vertex of the second sphere by less than the margin keeps them apart.
    let diag = 3.5f64.hypot(2.0 * 2f64.sqrt());
    let (p, t) = m.to_triangles();
    let half = p.len() / 2;
    for dir in [DVec3::X, -DVec3::X, DVec3::Y, DVec3::Z] {
        let mut q = p.clone();
        for x in &mut q[half..] {
            *x += dir * 0.4e-3 * diag;
        }
        assert!(
            intersecting_pairs(&q, &t).is_empty(),
            "margin violated along {dir}"
        );
    }
}

#[test]
fn step_limiter_blocks_a_step_through_the_opposite_wall() {
    let m = icosphere(3);
    let (before, t) = m.to_triangles();
    let mut proposed = before.clone();
    // Push the north cap through the south pole; nudge everything else a little.
    for (i, p) in proposed.iter_mut().enumerate() {
        if p.z > 0.9 {
            p.z = -1.5;
        } else {
            *p *= 1.0 + 0.001 * ((i % 7) as f64 - 3.0);
        }
    }
    let stats = limit_steps(&before, &mut proposed, &t, &LimiterOptions::default());
    assert!(intersecting_pairs(&proposed, &t).is_empty());
    assert!(stats.cancelled + stats.shortened > 0, "{stats:?}");
    assert!(
        stats.moved > stats.cancelled,
        "small steps are kept: {stats:?}"
    );
    let kept = (0..before.len())
        .filter(|&i| before[i].z <= 0.9 && proposed[i] != before[i])
        .count();
    assert!(kept > before.len() / 2);
}

/// Release timing: `cargo test --release -p roar-ops --test untangle_planted -- --ignored --nocapture`.
/// The limiter sees a typical optimizer step: every vertex moves 5 % of the mean edge length in
/// a pseudo-random direction; the best of 5 calls is reported.
#[test]
#[ignore]
fn timing_limiter_10k_and_untangle() {
    let m = icosphere(5); // 20480 faces
    let half = roar_mesh::shapes::torus(100, 50, 1.0, 0.3); // 10 000 faces
    for (label, mesh) in [("torus 10k", half), ("icosphere 20k", m)] {
        let (before, t) = mesh.to_triangles();
        let mean_edge =
            mesh.edges().map(|e| mesh.edge_length(e)).sum::<f64>() / mesh.n_edges() as f64;
        let step: Vec<DVec3> = (0..before.len())
            .map(|i| {
                let h = |k: usize| ((i * 7919 + k * 104_729) % 1000) as f64 / 500.0 - 1.0;
                DVec3::new(h(1), h(2), h(3)).normalize_or(DVec3::X) * 0.05 * mean_edge
            })
            .collect();
        let mut best = std::time::Duration::MAX;
        let mut stats = None;
        for _ in 0..5 {
            let mut proposed: Vec<DVec3> = before.iter().zip(&step).map(|(p, s)| *p + *s).collect();
            let start = std::time::Instant::now();
            stats = Some(limit_steps(
                &before,
                &mut proposed,
                &t,
                &LimiterOptions::default(),
            ));
            best = best.min(start.elapsed());
            assert!(intersecting_pairs(&proposed, &t).is_empty());
        }
        println!("{label}: limit_steps best of 5 {best:.2?}, {stats:?}");
    }
    check_untangled(two_spheres(4), "two spheres level 4");
    check_untangled(dented_disc(4), "dented disc level 4");
    let start = std::time::Instant::now();
    let (p, t) = two_spheres(4).to_triangles();
    let n = intersecting_pairs(&p, &t).len();
    println!(
        "one intersecting_pairs on two spheres level 4: {:.2?} ({n} pairs)",
        start.elapsed()
    );
}
