//! The render loss as a [`Loss`]: finite differences within a visibility cell,
//! zero against itself, descent under small gradient steps.

mod common;

use common::{Lcg, sphere};
use glam::DVec3;
use roar_loss::{CoarseViews, Loss, RenderLoss, TargetOptions, build_target, render_views};
use roar_render::{Camera, Image, LossKind, RenderOptions, render, star_cameras};

/// A sphere with a smooth bump, so the source differs from the target in shading and outline.
fn source(seed: u64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (mut p, t) = sphere(2, 0.7);
    let mut rng = Lcg(seed);
    for v in &mut p {
        *v *= 1.0 + 0.05 * rng.unit();
    }
    (p, t)
}

fn loss_against(
    target: &(Vec<DVec3>, Vec<[u32; 3]>),
    cameras: Vec<Camera>,
    kind: LossKind,
) -> RenderLoss {
    let targets = render_views(&target.0, &target.1, &cameras, true).unwrap();
    let mut loss = RenderLoss::from_renders(&cameras, &targets);
    loss.kind = kind;
    loss
}

/// Discrete state of one view: ids, (target, source, edge, branch) of every AA blend, and the
/// sign of every channel's difference to the target (the kinks of L1).
type ViewState = (Vec<u32>, Vec<(u32, u32, [u32; 2], bool)>, Vec<i8>);

/// The discrete state the loss is smooth within (as in the renderer's own gradient test).
fn ids(p: &[DVec3], t: &[[u32; 3]], cameras: &[Camera], targets: &[Image]) -> Vec<ViewState> {
    let r = render(p, t, cameras, &RenderOptions::default()).unwrap();
    r.views
        .into_iter()
        .zip(targets)
        .map(|(v, target)| {
            let items =
                v.aa.iter()
                    .map(|i| (i.target, i.source, i.edge, i.dalpha_dt > 0.0));
            let signs = v
                .rgba
                .iter()
                .zip(target)
                .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).signum() as i8))
                .collect();
            (v.ids, items.collect(), signs)
        })
        .collect()
}

fn directional_check(kind: LossKind, seed: u64) {
    let (pos, tris) = source(seed);
    let cameras = star_cameras(3, 2, 48, 48);
    let mut loss = loss_against(&sphere(2, 0.8), cameras.clone(), kind);
    let (_, grad) = loss.value_and_grad(&pos, &tris).unwrap();
    let mut rng = Lcg(seed * 31 + 7);
    let dir: Vec<DVec3> = pos.iter().map(|_| rng.vec3()).collect();
    let analytic: f64 = grad.iter().zip(&dir).map(|(g, d)| g.dot(*d)).sum();
    let moved = |s: f64| -> Vec<DVec3> { pos.iter().zip(&dir).map(|(p, d)| *p + s * *d).collect() };
    let base = ids(&pos, &tris, &cameras, &loss.targets);
    let mut h = 1e-5;
    while h > 1e-14
        && (ids(&moved(h), &tris, &cameras, &loss.targets) != base
            || ids(&moved(-h), &tris, &cameras, &loss.targets) != base)
    {
        h *= 0.5;
    }
    assert!(
        ids(&moved(h), &tris, &cameras, &loss.targets) == base,
        "no visibility cell found"
    );
    let mut at = |s: f64| loss.value_and_grad(&moved(s), &tris).unwrap().0;
    let fd = (at(h) - at(-h)) / (2.0 * h);
    let rel = (fd - analytic).abs() / analytic.abs().max(1e-300);
    assert!(analytic.abs() > 0.0);
    assert!(
        rel < 1e-5,
        "{kind:?}: analytic {analytic:e}, fd {fd:e}, h {h:e}, rel {rel:e}"
    );
}

#[test]
fn finite_difference_directional_derivative_l1() {
    directional_check(LossKind::L1, 1);
    directional_check(LossKind::L1, 2);
}

#[test]
fn finite_difference_directional_derivative_l2() {
    directional_check(LossKind::L2, 3);
}

#[test]
fn zero_loss_and_zero_gradient_against_itself() {
    // The target is rendered with culling, the source without: on a closed outward mesh the
    // two agree, so the L2 loss and its gradient vanish.
    let mesh = source(5);
    let cameras = star_cameras(3, 2, 48, 48);
    let mut loss = loss_against(&mesh, cameras, LossKind::L2);
    let (value, grad) = loss.value_and_grad(&mesh.0, &mesh.1).unwrap();
    assert!(value < 1e-12, "{value}");
    let worst = grad.iter().map(|g| g.length()).fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn a_fold_of_the_source_is_seen_because_the_source_is_not_culled() {
    // Reversing the source's faces shows their back sides: culled, it would render nothing; not
    // culled, it renders inward normals, far from the target.
    let mesh = sphere(2, 0.8);
    let cameras = star_cameras(2, 1, 32, 32);
    let mut loss = loss_against(&mesh, cameras, LossKind::L1);
    let inverted: Vec<[u32; 3]> = mesh.1.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let (same, _) = loss.value_and_grad(&mesh.0, &mesh.1).unwrap();
    let (flipped, _) = loss.value_and_grad(&mesh.0, &inverted).unwrap();
    // The f32 target images leave ~1e-8 of rounding per channel.
    assert!(same < 1e-7 && flipped > 0.1, "{same} {flipped}");
}

#[test]
fn loss_decreases_under_small_gradient_steps() {
    let target = sphere(2, 0.8);
    let cameras = star_cameras(3, 2, 64, 64);
    let mut loss = loss_against(&target, cameras, LossKind::L1);
    let (mut pos, tris) = source(8);
    let (start, _) = loss.value_and_grad(&pos, &tris).unwrap();
    let mut last = start;
    for _ in 0..5 {
        let (value, grad) = loss.value_and_grad(&pos, &tris).unwrap();
        last = value;
        let longest = grad.iter().map(|g| g.length()).fold(0.0, f64::max);
        for (p, g) in pos.iter_mut().zip(&grad) {
            *p -= 0.01 / longest * *g;
        }
    }
    let (end, _) = loss.value_and_grad(&pos, &tris).unwrap();
    assert!(end < last && last < start, "{start} → {last} → {end}");
}

#[test]
fn new_uses_the_targets_rig_and_renders() {
    let (p, t) = sphere(2, 3.0);
    let target = build_target(
        &p,
        &t,
        &TargetOptions {
            resolution: 32,
            ..TargetOptions::default()
        },
    )
    .unwrap();
    let mut loss = RenderLoss::new(&target);
    assert_eq!(loss.name(), "render");
    assert_eq!((loss.cameras.len(), loss.targets.len()), (36, 36));
    assert_eq!(loss.kind, LossKind::L1);
    assert!(!loss.options.cull_backfaces);
    let (value, grad) = loss
        .value_and_grad(&target.positions, &target.triangles)
        .unwrap();
    assert!(value < 1e-7, "{value}");
    assert_eq!(grad.len(), target.positions.len());
    // Bad input is an error, not a panic.
    assert!(
        loss.value_and_grad(&target.positions, &[[0, 1, 99_999]])
            .is_err()
    );
}

#[test]
fn coarse_views_render_the_first_iterations_then_the_full_rig() {
    let target = sphere(2, 0.8);
    let (pos, tris) = source(9);
    let fine = star_cameras(3, 2, 96, 96);
    let coarse = star_cameras(3, 2, 48, 48);
    let mut only_fine = loss_against(&target, fine.clone(), LossKind::L1);
    let mut only_coarse = loss_against(&target, coarse.clone(), LossKind::L1);
    let mut scheduled = loss_against(&target, fine, LossKind::L1).with_coarse(CoarseViews {
        targets: only_coarse.targets.clone(),
        cameras: coarse,
        until: 3,
    });
    let (fine_value, fine_grad) = only_fine.value_and_grad(&pos, &tris).unwrap();
    let (coarse_value, coarse_grad) = only_coarse.value_and_grad(&pos, &tris).unwrap();
    for (iteration, expected) in [(0, &coarse_grad), (2, &coarse_grad), (3, &fine_grad)] {
        scheduled.set_iteration(iteration);
        let (_, grad) = scheduled.value_and_grad(&pos, &tris).unwrap();
        assert_eq!(&grad, expected, "iteration {iteration}");
    }
    // A mean over pixels: half the side changes the value and the gradient's size little.
    assert!(
        (coarse_value / fine_value - 1.0).abs() < 0.2,
        "{coarse_value} vs {fine_value}"
    );
    let size = |g: &[DVec3]| g.iter().map(|g| g.length()).sum::<f64>();
    let ratio = size(&coarse_grad) / size(&fine_grad);
    assert!((ratio - 1.0).abs() < 0.3, "gradient size ratio {ratio}");
}
