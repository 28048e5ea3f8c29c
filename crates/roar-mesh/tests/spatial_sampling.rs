//! Area-weighted surface sampling: samples lie on positive-area faces, are reproducible from the
//! seed, and normalization maps a mesh into the rig sphere and back.

use glam::DVec3;
use proptest::prelude::*;
use roar_mesh::spatial::{Normalization, RIG_RADIUS, closest_point_on_triangle, sample_surface};

fn soup() -> impl Strategy<Value = (Vec<DVec3>, Vec<[u32; 3]>)> {
    let grid = (-2i32..=2, -2i32..=2, -2i32..=2)
        .prop_map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64));
    let float =
        (-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z));
    prop::collection::vec(prop_oneof![grid, float], 3..16).prop_flat_map(|positions| {
        let n = positions.len() as u32;
        (
            Just(positions),
            prop::collection::vec([0..n, 0..n, 0..n], 1..20),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn samples_lie_on_positive_area_faces((positions, triangles) in soup(), seed in any::<u64>()) {
        let s = sample_surface(&positions, &triangles, 200, seed);
        let area = |t: [u32; 3]| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        };
        let any_area = triangles.iter().any(|&t| area(t) > 0.0);
        prop_assert_eq!(s.len(), if any_area { 200 } else { 0 });
        prop_assert_eq!(s.normals.len(), s.len());
        prop_assert_eq!(s.faces.len(), s.len());
        prop_assert_eq!(s.barycentric.len(), s.len());
        for k in 0..s.len() {
            let t = triangles[s.faces[k] as usize];
            prop_assert!(area(t) > 0.0);
            let corners = t.map(|i| positions[i as usize]);
            let (q, _) = closest_point_on_triangle(s.points[k], corners);
            prop_assert!(q.distance(s.points[k]) < 1e-9);
            prop_assert!((s.normals[k].length() - 1.0).abs() < 1e-12);
            let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            prop_assert!(s.normals[k].dot(n) > 0.0);
        }
        prop_assert_eq!(&s, &sample_surface(&positions, &triangles, 200, seed));
    }

    #[test]
    fn normalization_fits_the_rig_sphere_and_round_trips((positions, triangles) in soup()) {
        let Some(norm) = Normalization::fit(&positions, &triangles) else {
            // Only when every referenced vertex coincides.
            let first = positions[triangles[0][0] as usize];
            prop_assert!(triangles.iter().flatten().all(|&i| positions[i as usize] == first));
            return Ok(());
        };
        let referenced: Vec<DVec3> = triangles.iter().flatten().map(|&i| positions[i as usize]).collect();
        let mut moved = referenced.clone();
        norm.apply_all(&mut moved);
        let farthest = moved.iter().map(|p| p.length()).fold(0.0, f64::max);
        prop_assert!((farthest - RIG_RADIUS).abs() < 1e-12);
        norm.invert_all(&mut moved);
        for (a, b) in moved.iter().zip(&referenced) {
            prop_assert!(a.distance(*b) < 1e-12);
        }
    }
}
