//! Behaviour of the forward pass: watertight fill, determinism, culling, pixel counts, errors,
//! and an optimization smoke test.

mod support;

use glam::DVec3;
use roar_mesh::shapes::icosphere;
use roar_render::camera::ProjectedVertex;
use roar_render::raster::rasterize;
use roar_render::{
    BACKGROUND, LossKind, RenderError, RenderOptions, face_pixel_counts, render,
    render_loss_and_grad, star_cameras, to_rgba8,
};
use support::{Rng, bumpy_sphere};

fn pv(x: f64, y: f64) -> ProjectedVertex {
    ProjectedVertex {
        x,
        y,
        z: 0.5,
        cx: 0.0,
        cy: 0.0,
        w: 1.0,
    }
}

/// Counts how many triangles of the fan cover each pixel, rasterizing them one at a time.
fn coverage(verts: &[ProjectedVertex], tris: &[[u32; 3]], size: u32) -> Vec<u32> {
    let mut counts = vec![0u32; (size * size) as usize];
    for t in tris {
        let r = rasterize(verts, std::slice::from_ref(t), size, size, false);
        for (c, &id) in counts.iter_mut().zip(&r.ids) {
            *c += (id != BACKGROUND) as u32;
        }
    }
    counts
}

#[test]
fn watertight_fan_covers_every_interior_pixel_exactly_once() {
    let size = 32u32;
    let mut rng = Rng(5);
    for case in 0..20 {
        // Centre on a pixel centre in case 0 (ties at a vertex), random otherwise; ring vertices
        // partly on pixel centres so edges pass exactly through samples.
        let centre = if case == 0 {
            [16.5, 16.5]
        } else {
            [16.0 + 3.0 * rng.next(), 16.0 + 3.0 * rng.next()]
        };
        let n = 5 + case % 9;
        let mut verts = vec![pv(centre[0], centre[1])];
        for i in 0..n {
            let ang = i as f64 / n as f64 * std::f64::consts::TAU + 0.2 * rng.next();
            let r = 12.0 + 2.0 * rng.next();
            let (x, y) = (centre[0] + r * ang.cos(), centre[1] + r * ang.sin());
            let (x, y) = if i % 2 == 0 {
                (x.floor() + 0.5, y.floor() + 0.5)
            } else {
                (x, y)
            };
            verts.push(pv(x, y));
        }
        let ring = n as u32;
        // Alternate winding per triangle: the fill rule must not care about orientation.
        let tris: Vec<[u32; 3]> = (0..ring)
            .map(|i| {
                let (a, b) = (1 + i, 1 + (i + 1) % ring);
                if i % 2 == 0 { [0, a, b] } else { [0, b, a] }
            })
            .collect();
        let counts = coverage(&verts, &tris, size);
        // Pixels whose centres are inside the ring polygon (by a full fan test in f64, away
        // from the outer boundary) must be covered exactly once; no pixel ever twice.
        let poly: Vec<[f64; 2]> = verts[1..].iter().map(|v| [v.x, v.y]).collect();
        for y in 0..size {
            for x in 0..size {
                let c = counts[(y * size + x) as usize];
                assert!(c <= 1, "case {case}: pixel ({x}, {y}) covered {c} times");
                let p = [x as f64 + 0.5, y as f64 + 0.5];
                if inside_with_margin(&poly, p, 1e-6) {
                    assert_eq!(c, 1, "case {case}: interior pixel ({x}, {y}) missed");
                }
            }
        }
    }
}

/// Whether `p` lies inside the star-shaped polygon (ordered ring) and at least `margin` away
/// from every edge.
fn inside_with_margin(poly: &[[f64; 2]], p: [f64; 2], margin: f64) -> bool {
    let n = poly.len();
    let mut winding = 0.0;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let (ax, ay, bx, by) = (a[0] - p[0], a[1] - p[1], b[0] - p[0], b[1] - p[1]);
        winding += (ax * by - ay * bx).atan2(ax * bx + ay * by);
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let len2 = ex * ex + ey * ey;
        let s = (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len2).clamp(0.0, 1.0);
        let (dx, dy) = (a[0] + s * ex - p[0], a[1] + s * ey - p[1]);
        if (dx * dx + dy * dy).sqrt() < margin {
            return false;
        }
    }
    winding.abs() > 1.0
}

#[test]
fn rendering_determinism_under_triangle_order_and_thread_count() {
    let (pos, tris) = bumpy_sphere(2, 0.8, 0.05, 21);
    let cams = star_cameras(3, 2, 40, 40);
    let opts = RenderOptions::default();
    let run = |threads: usize, tris: &[[u32; 3]]| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| render(&pos, tris, &cams, &opts).unwrap())
    };
    let a = run(1, &tris);
    let b = run(2, &tris);
    assert_eq!(a, b, "thread count changed the render");
    // Reverse the triangle list: face i becomes face n−1−i.
    let rev: Vec<[u32; 3]> = tris.iter().rev().copied().collect();
    let c = run(2, &rev);
    let n = tris.len() as u32;
    for (va, vc) in a.views.iter().zip(&c.views) {
        let mapped: Vec<u32> = vc
            .ids
            .iter()
            .map(|&i| if i == BACKGROUND { i } else { n - 1 - i })
            .collect();
        assert_eq!(va.ids, mapped);
        assert_eq!(va.rgba, vc.rgba, "triangle order changed the image");
    }
    // Gradients are bit-identical across thread counts too.
    let targets: Vec<_> = a
        .views
        .iter()
        .map(|v| {
            v.rgba
                .iter()
                .map(|p| [p[0] * 0.5, p[1], p[2], p[3]])
                .collect()
        })
        .collect();
    let grad = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            render_loss_and_grad(&pos, &tris, &cams, &targets, &opts, LossKind::L1).unwrap()
        })
    };
    assert_eq!(grad(1), grad(2));
}

#[test]
fn culling_and_face_pixel_counts_pick_the_outward_twin_of_a_soup() {
    // An outward sphere plus every face's reversed twin (faces n..2n).
    let (pos, tris) = icosphere(2).to_triangles();
    let n = tris.len();
    let mut soup = tris.clone();
    soup.extend(tris.iter().map(|t| [t[0], t[2], t[1]]));
    let cams = star_cameras(2, 2, 48, 48);
    let pos: Vec<DVec3> = pos.iter().map(|p| *p * 0.9).collect();
    let opts = RenderOptions {
        cull_backfaces: true,
        antialias: true,
    };
    let culled = face_pixel_counts(&render(&pos, &soup, &cams, &opts).unwrap());
    let counts = culled.clone();
    assert_eq!(counts.len(), 2 * n);
    assert!(counts[..n].iter().sum::<u32>() > 1000);
    assert_eq!(
        counts[n..].iter().sum::<u32>(),
        0,
        "inward twins are never visible with culling"
    );
    // Without culling each twin pair ties in depth and shares the same pixels.
    let counts = face_pixel_counts(&render(&pos, &soup, &cams, &RenderOptions::default()).unwrap());
    for f in 0..n {
        assert_eq!(counts[f] + counts[f + n], culled[f], "face {f}");
    }
}

#[test]
fn flat_shading_writes_raw_normals_and_alpha() {
    let (pos, tris) = icosphere(1).to_triangles();
    let cams = star_cameras(1, 1, 32, 32);
    let r = render(
        &pos,
        &tris,
        &cams,
        &RenderOptions {
            cull_backfaces: false,
            antialias: false,
        },
    )
    .unwrap();
    let v = &r.views[0];
    let centre = (16 * 32 + 16) as usize;
    let id = v.ids[centre] as usize;
    let t = tris[id];
    let n = (pos[t[1] as usize] - pos[t[0] as usize])
        .cross(pos[t[2] as usize] - pos[t[0] as usize])
        .normalize();
    assert!(
        n.z > 0.5,
        "the visible face at the centre faces the camera (+z)"
    );
    for c in 0..3 {
        assert!((v.rgba[centre][c] as f64 - n[c]).abs() < 1e-6);
    }
    assert_eq!(v.rgba[centre][3], 1.0);
    assert_eq!(v.rgba[0], [0.0; 4]);
    let bytes = to_rgba8(&v.rgba);
    assert_eq!(bytes.len(), 32 * 32 * 4);
    assert_eq!(&bytes[..4], &[0, 0, 0, 0]);
    assert_eq!(bytes[centre * 4 + 3], 255);
}

#[test]
fn bad_input_gives_errors_not_garbage() {
    let cams = star_cameras(1, 1, 8, 8);
    let tri = [[0u32, 1, 2]];
    let behind = [DVec3::new(0.0, 0.0, 9.5), DVec3::X, DVec3::Y];
    assert_eq!(
        render(&behind, &tri, &cams, &RenderOptions::default()),
        Err(RenderError::BehindNearPlane {
            vertex: 0,
            camera: 0
        })
    );
    let ok = [DVec3::ZERO, DVec3::X, DVec3::Y];
    assert!(matches!(
        render(&ok, &[[0, 1, 3]], &cams, &RenderOptions::default()),
        Err(RenderError::IndexOutOfRange {
            face: 0,
            vertex: 3,
            ..
        })
    ));
    let nan = [DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0), DVec3::Y];
    assert!(matches!(
        render(&nan, &tri, &cams, &RenderOptions::default()),
        Err(RenderError::NonFiniteVertex { vertex: 1 })
    ));
    let empty = star_cameras(1, 1, 0, 8);
    assert!(matches!(
        render(&ok, &tri, &empty, &RenderOptions::default()),
        Err(RenderError::EmptyResolution { .. })
    ));
    // Empty meshes render as background.
    let r = render(&[], &[], &cams, &RenderOptions::default()).unwrap();
    assert!(r.views[0].ids.iter().all(|&i| i == BACKGROUND));
}

#[test]
fn optimization_smoke_sphere_to_ellipsoid_halves_the_loss() {
    let (sphere, tris) = icosphere(3).to_triangles();
    let cams = star_cameras(3, 2, 64, 64);
    let opts = RenderOptions::default();
    let ellipsoid: Vec<DVec3> = sphere
        .iter()
        .map(|p| *p * DVec3::new(0.85, 0.55, 0.7))
        .collect();
    let targets: Vec<_> = render(&ellipsoid, &tris, &cams, &opts)
        .unwrap()
        .views
        .into_iter()
        .map(|v| v.rgba)
        .collect();
    let mut pos: Vec<DVec3> = sphere.iter().map(|p| *p * 0.7).collect();
    let (first, _) =
        render_loss_and_grad(&pos, &tris, &cams, &targets, &opts, LossKind::L1).unwrap();
    let mut last = first;
    for _ in 0..100 {
        let (loss, grad) =
            render_loss_and_grad(&pos, &tris, &cams, &targets, &opts, LossKind::L1).unwrap();
        last = loss;
        // Plain gradient descent with the step normalized by the largest vertex gradient.
        let max = grad
            .iter()
            .map(|g| g.length())
            .fold(0.0, f64::max)
            .max(1e-300);
        for (p, g) in pos.iter_mut().zip(&grad) {
            *p -= *g * (0.004 / max);
        }
    }
    println!("smoke: loss {first} -> {last}");
    assert!(last < 0.5 * first, "loss {first} -> {last}");
}
