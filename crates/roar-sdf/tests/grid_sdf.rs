//! Dense grid SDFs from `.npy` volumes: trilinear values and gradients (against finite
//! differences and against the sampled sphere), float32/float64 and C/Fortran order read alike,
//! the sidecar's bounds, and one-line errors for bad volumes and sidecars.

use glam::DVec3;
use ndarray::{Array, Array3, ArrayD, IxDyn, ShapeBuilder};
use ndarray_npy::WriteNpyExt;
use roar_mesh::spatial::{Aabb, Sdf, evaluate_with_gradients};
use roar_sdf::{DEFAULT_BOUNDS, GridSdf, SdfError, load_sdf_input};

/// Deterministic pseudo-random numbers in [-1, 1).
fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

const RADIUS: f64 = 0.6;

/// The bounds of the test grids: not a cube, not centred.
fn bounds() -> Aabb {
    Aabb {
        min: DVec3::new(-0.9, -1.0, -0.8),
        max: DVec3::new(1.0, 0.8, 0.9),
    }
}

/// The sample point of `[i][j][k]` on an `n`-per-axis grid over `bounds`.
fn sample(bounds: &Aabb, n: [usize; 3], ijk: [usize; 3]) -> DVec3 {
    let t = DVec3::new(
        ijk[0] as f64 / (n[0] - 1) as f64,
        ijk[1] as f64 / (n[1] - 1) as f64,
        ijk[2] as f64 / (n[2] - 1) as f64,
    );
    bounds.min + t * (bounds.max - bounds.min)
}

/// `|p| − RADIUS` sampled on an `n` grid over [`bounds`], in logical `[i][j][k]` order.
fn sphere_volume(n: [usize; 3]) -> Array3<f64> {
    let b = bounds();
    Array3::from_shape_fn((n[0], n[1], n[2]), |(i, j, k)| {
        sample(&b, n, [i, j, k]).length() - RADIUS
    })
}

fn npy_bytes<A: ndarray_npy::WritableElement, D: ndarray::Dimension>(
    array: &Array<A, D>,
) -> Vec<u8> {
    let mut bytes = Vec::new();
    array.write_npy(&mut bytes).unwrap();
    bytes
}

#[test]
fn trilinear_values_interpolate_the_samples_and_gradients_match_finite_differences() {
    let n = [33, 29, 31];
    let grid = GridSdf::from_npy_bytes(&npy_bytes(&sphere_volume(n)), bounds()).unwrap();
    // At the samples the field is the sampled value.
    let b = bounds();
    for ijk in [[0, 0, 0], [32, 28, 30], [16, 3, 20], [5, 27, 0]] {
        let p = sample(&b, n, ijk);
        let mut v = [0.0];
        grid.values(&[p], &mut v);
        assert!((v[0] - (p.length() - RADIUS)).abs() < 1e-12, "{ijk:?}");
    }
    // Between samples: within the interpolation error of the sphere's distance (cell ≈ 0.06).
    let mut r = rng(3);
    let points: Vec<DVec3> = (0..3000)
        .map(|_| {
            let t = 0.5 * (DVec3::new(r(), r(), r()) + 1.0);
            b.min + t * (b.max - b.min)
        })
        .collect();
    let (values, gradients) = evaluate_with_gradients(&grid, &points);
    let mut bad = 0;
    let h = 1e-7;
    for ((p, f), g) in points.iter().zip(&values).zip(&gradients) {
        // |p| is smooth away from its apex at the origin.
        if p.length() > 0.2 {
            assert!(
                (f - (p.length() - RADIUS)).abs() < 5e-3,
                "value at {p}: {f}"
            );
            assert!(
                g.normalize().dot(p.normalize()) > 0.98,
                "gradient at {p}: {g}"
            );
        }
        let mut fd = DVec3::ZERO;
        for axis in 0..3 {
            let e = DVec3::AXES[axis] * h;
            let mut v = [0.0; 2];
            grid.values(&[*p + e, *p - e], &mut v);
            fd[axis] = (v[0] - v[1]) / (2.0 * h);
        }
        // A difference that straddles a cell face is not a derivative of either cell.
        if (fd - *g).length() > 1e-5 {
            bad += 1;
        }
    }
    assert!(bad <= 10, "{bad} of 3000 gradients off");
    assert_eq!(grid.evaluations().gradients, 3000);
    // Outside the box the field grows with the distance to it, with a consistent gradient.
    let p = DVec3::new(1.5, 0.2, -1.2);
    let (v, g) = evaluate_with_gradients(&grid, &[p]);
    let q = p.clamp(b.min, b.max);
    assert!((v[0] - ((q.length() - RADIUS) + (p - q).length())).abs() < 5e-3);
    let mut fd = DVec3::ZERO;
    for axis in 0..3 {
        let e = DVec3::AXES[axis] * 1e-6;
        let mut v = [0.0; 2];
        grid.values(&[p + e, p - e], &mut v);
        fd[axis] = (v[0] - v[1]) / 2e-6;
    }
    assert!((fd - g[0]).length() < 1e-5, "outside: {fd} vs {}", g[0]);
}

#[test]
fn float32_and_fortran_order_volumes_read_as_the_same_field() {
    let n = [9, 7, 8];
    let c64 = sphere_volume(n);
    let reference = GridSdf::from_npy_bytes(&npy_bytes(&c64), bounds()).unwrap();
    let mut fortran = Array3::<f64>::zeros((n[0], n[1], n[2]).f());
    fortran.assign(&c64);
    let c32 = c64.mapv(|v| v as f32);
    let mut r = rng(5);
    let points: Vec<DVec3> = (0..200).map(|_| 0.9 * DVec3::new(r(), r(), r())).collect();
    let (want, _) = evaluate_with_gradients(&reference, &points);
    for (name, bytes, tolerance) in [
        ("f64 Fortran", npy_bytes(&fortran), 1e-15),
        ("f32 C", npy_bytes(&c32), 1e-6),
    ] {
        let grid = GridSdf::from_npy_bytes(&bytes, bounds()).unwrap();
        assert_eq!(grid.dims(), n, "{name}");
        let (got, _) = evaluate_with_gradients(&grid, &points);
        for (a, b) in got.iter().zip(&want) {
            assert!((a - b).abs() <= tolerance, "{name}: {a} vs {b}");
        }
    }
}

#[test]
fn the_sidecar_places_the_grid_and_a_missing_one_leaves_the_fallback() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ball.npy");
    let n = [17, 17, 17];
    std::fs::write(&path, npy_bytes(&sphere_volume(n))).unwrap();
    let loaded = load_sdf_input(&path, DEFAULT_BOUNDS).unwrap();
    assert!(loaded.bounds.is_none());
    let b = bounds();
    std::fs::write(
        dir.path().join("ball.json"),
        format!(
            r#"{{"min": [{}, {}, {}], "max": [{}, {}, {}]}}"#,
            b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
        ),
    )
    .unwrap();
    let loaded = load_sdf_input(&path, DEFAULT_BOUNDS).unwrap();
    assert_eq!(loaded.bounds, Some(b));
    // Placed over the sidecar's bounds: the sample [8][8][8] is that box's centre.
    let mut v = [0.0];
    loaded.field.values(&[b.center()], &mut v);
    let centre = sample(&b, n, [8, 8, 8]);
    assert!((v[0] - (centre.length() - RADIUS)).abs() < 1e-12);
}

fn grid_error(bytes: Vec<u8>) -> String {
    let error = GridSdf::from_npy_bytes(&bytes, bounds()).unwrap_err();
    assert!(matches!(error, SdfError::Grid(_)), "{error:?}");
    let message = error.to_string();
    assert!(!message.contains('\n'), "{message}");
    message
}

#[test]
fn bad_volumes_and_sidecars_get_one_line_errors() {
    let flat = ArrayD::<f32>::zeros(IxDyn(&[4, 4]));
    assert!(grid_error(npy_bytes(&flat)).contains("has 2 axes [4, 4]"));
    let thin = Array3::<f64>::zeros((4, 1, 4));
    assert!(grid_error(npy_bytes(&thin)).contains("4 × 1 × 4"));
    let mut holed = sphere_volume([5, 5, 5]);
    holed[[1, 2, 3]] = f64::NAN;
    assert!(grid_error(npy_bytes(&holed)).contains("NaN at [1, 2, 3]"));
    let mut infinite = sphere_volume([5, 5, 5]).mapv(|v| v as f32);
    infinite[[4, 0, 2]] = f32::INFINITY;
    assert!(grid_error(npy_bytes(&infinite)).contains("inf at [4, 0, 2]"));
    let ints = Array3::<i32>::zeros((3, 3, 3));
    assert!(grid_error(npy_bytes(&ints)).contains("float32/float64"));
    let mut truncated = npy_bytes(&sphere_volume([5, 5, 5]));
    truncated.truncate(truncated.len() - 7);
    assert!(grid_error(truncated).contains("float32/float64"));
    assert!(grid_error(b"not an npy file".to_vec()).contains("float32/float64"));
    let error = GridSdf::from_npy_bytes(
        &npy_bytes(&sphere_volume([3, 3, 3])),
        Aabb {
            min: DVec3::ONE,
            max: DVec3::new(2.0, 0.0, 2.0),
        },
    )
    .unwrap_err();
    assert!(error.to_string().contains("not a box"), "{error}");

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("g.npy");
    std::fs::write(&path, npy_bytes(&sphere_volume([3, 3, 3]))).unwrap();
    for (sidecar, expected) in [
        (r#"{"min": [0, 0], "max": [1, 1, 1]}"#, "expected {\"min\""),
        (r#"{"min": [0, 0, 0], "max": [1, 1, 1], "size": 2}"#, "size"),
        (r#"{"min": [0, 0, 0], "max": [1, -1, 1]}"#, "not a box"),
        ("{", "g.json"),
    ] {
        std::fs::write(dir.path().join("g.json"), sidecar).unwrap();
        let message = match load_sdf_input(&path, DEFAULT_BOUNDS) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{sidecar} accepted"),
        };
        assert!(message.contains(expected), "{sidecar}: {message}");
        assert!(!message.contains('\n'), "{message}");
    }
}
