//! End-to-end gradient checks of the renderer against finite differences.

mod support;

use glam::DVec3;
use roar_render::{
    Camera, LossKind, RenderOptions, image_loss, render, render_loss_and_grad, star_cameras,
};
use support::{Rng, bumpy_sphere};

/// Discrete state of one view: ids and (target, source, edge, branch) of every AA item.
type ViewSignature = (Vec<u32>, Vec<(u32, u32, [u32; 2], bool)>);

/// Identity of the discrete state of a render: ids and the structure of every AA item.
fn signature(p: &[DVec3], f: &[[u32; 3]], cams: &[Camera]) -> Vec<ViewSignature> {
    let r = render(p, f, cams, &RenderOptions::default()).unwrap();
    r.views
        .into_iter()
        .map(|v| {
            let items =
                v.aa.iter()
                    .map(|i| (i.target, i.source, i.edge, i.dalpha_dt > 0.0))
                    .collect();
            (v.ids, items)
        })
        .collect()
}

fn directional_check(kind: LossKind, seed: u64) {
    let (pos, tris) = bumpy_sphere(2, 0.8, 0.06, seed);
    let (target_pos, _) = bumpy_sphere(2, 0.85, 0.08, seed + 100);
    let cams: Vec<Camera> = star_cameras(3, 1, 48, 48);
    let opts = RenderOptions::default();
    let targets: Vec<_> = render(&target_pos, &tris, &cams, &opts)
        .unwrap()
        .views
        .into_iter()
        .map(|v| v.rgba)
        .collect();
    let (_, grad) = render_loss_and_grad(&pos, &tris, &cams, &targets, &opts, kind).unwrap();
    let mut rng = Rng(seed * 7 + 1);
    let dir: Vec<DVec3> = pos.iter().map(|_| rng.vec3()).collect();
    let analytic: f64 = grad.iter().zip(&dir).map(|(g, d)| g.dot(*d)).sum();
    let moved = |s: f64| -> Vec<DVec3> { pos.iter().zip(&dir).map(|(p, d)| *p + *d * s).collect() };
    let mut h = 1e-5;
    let sig = signature(&pos, &tris, &cams);
    for _ in 0..30 {
        if signature(&moved(h), &tris, &cams) == sig && signature(&moved(-h), &tris, &cams) == sig {
            break;
        }
        h *= 0.5;
    }
    assert_eq!(
        signature(&moved(h), &tris, &cams),
        sig,
        "no visibility cell found"
    );
    let loss_at = |s: f64| {
        render_loss_and_grad(&moved(s), &tris, &cams, &targets, &opts, kind)
            .unwrap()
            .0
    };
    let fd = (loss_at(h) - loss_at(-h)) / (2.0 * h);
    let rel = (fd - analytic).abs() / analytic.abs().max(1e-300);
    assert!(
        rel < 1e-5,
        "{kind:?}: analytic {analytic:e}, fd {fd:e} (h {h:e}), rel {rel:e}"
    );
}

#[test]
fn end_to_end_directional_finite_difference_l1() {
    directional_check(LossKind::L1, 1);
    directional_check(LossKind::L1, 2);
}

#[test]
fn end_to_end_directional_finite_difference_l2() {
    directional_check(LossKind::L2, 3);
    directional_check(LossKind::L2, 4);
}

#[test]
fn fused_path_matches_render_image_loss_backward() {
    let (pos, tris) = bumpy_sphere(1, 0.8, 0.05, 9);
    let (tpos, _) = bumpy_sphere(1, 0.7, 0.05, 10);
    let cams = star_cameras(2, 2, 32, 32);
    let opts = RenderOptions::default();
    let targets: Vec<_> = render(&tpos, &tris, &cams, &opts)
        .unwrap()
        .views
        .into_iter()
        .map(|v| v.rgba)
        .collect();
    let r = render(&pos, &tris, &cams, &opts).unwrap();
    let (l2, d_img) = image_loss(&r, &targets, LossKind::L2).unwrap();
    let g2 = roar_render::backward(&pos, &tris, &cams, &r, &d_img).unwrap();
    let (l1, g1) = render_loss_and_grad(&pos, &tris, &cams, &targets, &opts, LossKind::L2).unwrap();
    // The unfused path reads the f32 image; the fused one stays in f64.
    assert!((l1 - l2).abs() < 1e-6 * l1.abs(), "{l1} vs {l2}");
    for (a, b) in g1.iter().zip(&g2) {
        assert!(
            (*a - *b).length() < 1e-5 * a.length().max(1e-6),
            "{a} vs {b}"
        );
    }
}

#[test]
fn gradient_of_target_against_itself_is_zero_for_l2() {
    let (pos, tris) = bumpy_sphere(1, 0.8, 0.05, 11);
    let cams = star_cameras(2, 2, 32, 32);
    let opts = RenderOptions::default();
    let (loss, grad) = {
        let targets: Vec<_> = render(&pos, &tris, &cams, &opts)
            .unwrap()
            .views
            .into_iter()
            .map(|v| v.rgba)
            .collect();
        render_loss_and_grad(&pos, &tris, &cams, &targets, &opts, LossKind::L2).unwrap()
    };
    assert!(loss < 1e-12, "{loss}");
    assert!(
        grad.iter().all(|g| g.length() < 1e-6),
        "max {:?}",
        grad.iter().map(|g| g.length()).fold(0.0, f64::max)
    );
}

/// A flat square of half-size `half` (world units) in the z = 0 plane, rotated by `angle` about
/// z and shifted by `shift`, facing camera 0 of a 1×1 rig (which looks down −z).
fn square(half: f64, angle: f64, shift: DVec3) -> Vec<DVec3> {
    let (s, c) = angle.sin_cos();
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| DVec3::new(half * (c * x - s * y), half * (s * x + c * y), 0.0) + shift)
        .collect()
}

#[test]
fn silhouette_shift_gradient_sign_and_magnitude() {
    let tris = [[0u32, 1, 2], [0, 2, 3]];
    let cams = star_cameras(1, 1, 32, 32);
    let opts = RenderOptions::default();
    let px = 2.0 / 32.0; // world units per pixel at distance 10
    for &angle in &[0.0, 0.35] {
        for axis in [DVec3::X, DVec3::Y] {
            let target: Vec<_> = render(&square(0.43, angle, DVec3::ZERO), &tris, &cams, &opts)
                .unwrap()
                .views
                .into_iter()
                .map(|v| v.rgba)
                .collect();
            let loss_grad = |s: f64| {
                let p = square(0.43, angle, axis * s * px);
                let (l, g) =
                    render_loss_and_grad(&p, &tris, &cams, &target, &opts, LossKind::L2).unwrap();
                (l, g.iter().map(|v| v.dot(axis) * px).sum::<f64>())
            };
            let (_, g0) = loss_grad(0.0);
            assert!(g0.abs() < 1e-9, "zero gradient at the target, got {g0}");
            for s in [-1.6, -0.9, -0.55, -0.3, 0.3, 0.55, 0.9, 1.6] {
                let (_, g) = loss_grad(s);
                let fd = (loss_grad(s + 0.125).0 - loss_grad(s - 0.125).0) / 0.25;
                // The loss is piecewise smooth (kinks where an edge crosses a pixel boundary), so
                // the finite difference over a quarter pixel equals the mean derivative over that
                // interval: compare it with the analytic gradient averaged by the midpoint rule.
                let g_mean = (0..8)
                    .map(|k| loss_grad(s - 0.125 + (k as f64 + 0.5) / 32.0).1)
                    .sum::<f64>()
                    / 8.0;
                assert!(
                    g.signum() == s.signum() && fd.signum() == s.signum(),
                    "angle {angle} axis {axis} s {s}: g {g}, fd {fd}"
                );
                assert!(
                    (g_mean - fd).abs() < 0.2 * fd.abs(),
                    "angle {angle} axis {axis} s {s}: mean g {g_mean}, fd {fd}"
                );
            }
        }
    }
}
