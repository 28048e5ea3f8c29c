//! The exact-closest-point Chamfer: known distances between polyhedra, no floor for a mesh against
//! itself, and the same answer whatever the thread count.

mod common;

use common::shapes::{icosphere, torus};
use glam::DVec3;
use roar_eval::{ChamferOptions, FidelityStats, fidelity};

fn options(samples: usize, seed: u64) -> ChamferOptions {
    ChamferOptions { samples, seed }
}

/// The square `[0,1]² × {z}` as two triangles wound towards +z.
fn square(z: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let p = vec![
        DVec3::new(0.0, 0.0, z),
        DVec3::new(1.0, 0.0, z),
        DVec3::new(1.0, 1.0, z),
        DVec3::new(0.0, 1.0, z),
    ];
    (p, vec![[0, 1, 2], [0, 2, 3]])
}

#[test]
fn parallel_squares_read_their_gap_exactly_while_the_sampled_chamfer_reads_more() {
    let gap = 0.01;
    let (p, t) = square(gap);
    let (rp, rt) = square(0.0);
    let f = fidelity(&p, &t, &rp, &rt, &options(20_000, 2)).unwrap();
    // Every sample lies straight above or below a point of the other square; only the rounding
    // of a 40k-term mean is left.
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * y;
    assert!(close(f.chamfer_exact, gap), "{}", f.chamfer_exact);
    let diag = 2f64.sqrt();
    assert!(close(f.chamfer_exact_over_diag, gap / diag));
    assert!(close(f.hausdorff_exact_over_diag, gap / diag));
    assert!(close(f.normal_cosine_exact, 1.0));
    assert!(close(f.normal_cosine_exact_abs, 1.0));
    // Nearest samples are rarely straight across: the sampled measure sits above the gap.
    assert!(f.chamfer_l2 > gap * 1.01, "sampled {}", f.chamfer_l2);
}

/// Smallest distance from the centre to a face plane of `(p, t)`, over the largest distance from
/// the centre to a vertex: the polyhedron lies between the spheres of these two radii.
fn inner_over_outer_radius(p: &[DVec3], t: &[[u32; 3]]) -> f64 {
    let outer = p.iter().map(|q| q.length()).fold(0.0, f64::max);
    let inner = t
        .iter()
        .map(|&[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|i| p[i as usize]);
            (b - a).cross(c - a).normalize().dot(a).abs()
        })
        .fold(f64::INFINITY, f64::min);
    inner / outer
}

#[test]
fn concentric_icospheres_read_the_radius_gap_within_the_tessellation_bound() {
    let (r, big_r) = (1.0, 1.1);
    let (p_in, t_in) = icosphere(r, 4);
    let (p_out, t_out) = icosphere(big_r, 4);
    // Both polyhedra are convex and scaled copies: each lies between the spheres of radii h·ρ and
    // ρ (ρ its vertex radius). A point of one is then between `R·h − r` and `R − r·h` from the
    // other, in either direction, so every sample distance lies in that interval.
    let h = inner_over_outer_radius(&p_in, &t_in);
    let (lo, hi) = (big_r * h - r, big_r - r * h);
    assert!(
        hi - lo < 0.01,
        "the bound is tight enough to test: [{lo}, {hi}]"
    );
    let f = fidelity(&p_out, &t_out, &p_in, &t_in, &options(50_000, 3)).unwrap();
    assert!(
        f.chamfer_exact >= lo && f.chamfer_exact <= hi,
        "chamfer_exact {} outside [{lo}, {hi}]",
        f.chamfer_exact
    );
    let hausdorff = f.hausdorff_exact_over_diag * f.reference_diagonal;
    assert!(hausdorff >= f.chamfer_exact && hausdorff <= hi + 1e-12);
    assert!((f.chamfer_exact_over_diag - f.chamfer_exact / f.reference_diagonal).abs() < 1e-15);
    assert!(f.normal_cosine_exact > 0.99 && f.normal_cosine_exact_abs >= f.normal_cosine_exact);
}

#[test]
fn inverted_winding_flips_the_signed_exact_cosine_only() {
    let (p, t) = icosphere(1.0, 3);
    let inverted: Vec<[u32; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let f = fidelity(&p, &inverted, &p, &t, &options(20_000, 1)).unwrap();
    assert!(f.normal_cosine_exact < -0.999, "{}", f.normal_cosine_exact);
    assert!(f.normal_cosine_exact_abs > 0.999);
}

#[test]
fn a_mesh_against_itself_reads_zero_exactly_but_not_when_sampled() {
    let (p, t) = torus(2.0, 0.5, 48, 24);
    let f = fidelity(&p, &t, &p, &t, &options(50_000, 5)).unwrap();
    assert!(
        f.chamfer_exact_over_diag <= 1e-12,
        "{}",
        f.chamfer_exact_over_diag
    );
    assert!(f.hausdorff_exact_over_diag <= 1e-12);
    assert!(f.normal_cosine_exact > 0.9999, "{}", f.normal_cosine_exact);
    // The sampled measure keeps its floor: the spacing of the other side's samples.
    assert!(
        f.chamfer_l2_over_diag > 1e-4,
        "sampled {}",
        f.chamfer_l2_over_diag
    );
}

fn with_threads(threads: usize, run: impl FnOnce() -> FidelityStats + Send) -> FidelityStats {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(run)
}

#[test]
fn exact_chamfer_is_the_same_at_one_and_two_threads() {
    // Enough samples for many parallel chunks on each side.
    let (p, t) = torus(2.0, 0.5, 40, 20);
    let (rp, rt) = icosphere(2.4, 3);
    let run = || fidelity(&p, &t, &rp, &rt, &options(60_000, 11)).unwrap();
    let one = with_threads(1, run);
    let two = with_threads(2, run);
    assert_eq!(one, two);
    assert!(one.chamfer_exact > 0.0);
}
