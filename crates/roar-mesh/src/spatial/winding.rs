//! Generalized winding numbers of triangle soups: the point cloud's sample filter, the
//! watertight init's enclosure rule, the ray-cast projector's guards and the untangle's probes.
//!
//! The winding number of a soup at a point `q` is `w(q) = (1/4π) Σ_t Ω_t(q)`, the signed solid
//! angles of its triangles seen from `q`. For a closed, outward-oriented mesh it is 1 inside and 0
//! outside; reversing the orientation negates it; for open or messy soups it varies smoothly and
//! stays a robust inside/outside indicator (Jacobson et al. 2013).
//!
//! [`exact_winding_number`] sums the exact solid angles (Van Oosterom–Strackee, `atan2` form) and
//! is the oracle. [`WindingNumber`] is the fast version of Barill et al. 2018 ("Fast Winding
//! Numbers for Soups and Clouds"): a bounding hierarchy over triangle centroids whose nodes carry
//! a Taylor expansion of their triangles' dipole field about the node's area-weighted centroid:
//! the dipole term Σ a·n and the next two terms, with exact per-triangle moments (Barill's "order
//! 2", i.e. up to the second derivative of the kernel; this was needed: with the first two terms
//! only, a closed sphere read 1.05 inside at β = 2). A node whose
//! expansion centre is farther than `β × radius` from the query is evaluated by its expansion;
//! nearer nodes are opened, and leaves are summed exactly.

use glam::{DMat3, DVec3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// A triangle refers to a vertex that does not exist.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "triangle {triangle} refers to vertex {vertex}, but there are only {vertex_count} vertices"
)]
pub struct TriangleIndexError {
    /// Index of the offending triangle.
    pub triangle: usize,
    /// The out-of-range vertex index it holds.
    pub vertex: u32,
    /// Number of vertices in the position buffer.
    pub vertex_count: usize,
}

/// Checks that every triangle's indices are in range for `vertex_count` vertices.
///
/// Returns the first offending triangle, so callers can refuse bad input instead of panicking.
pub fn check_triangle_indices(
    vertex_count: usize,
    triangles: &[[u32; 3]],
) -> Result<(), TriangleIndexError> {
    for (triangle, tri) in triangles.iter().enumerate() {
        for &vertex in tri {
            if vertex as usize >= vertex_count {
                return Err(TriangleIndexError {
                    triangle,
                    vertex,
                    vertex_count,
                });
            }
        }
    }
    Ok(())
}

/// Signed solid angle of triangle `(a, b, c)` seen from `q`, in steradians, in `(−2π, 2π]`.
///
/// Van Oosterom–Strackee formula in its `atan2` form, which stays accurate for tiny and for
/// nearly-flat configurations. Positive when `q` is on the back side of the triangle (the side its
/// normal `(b−a)×(c−a)` points away from), so points inside an outward-oriented closed mesh get a
/// total of `4π`. A query exactly on the triangle's plane or a vertex gives 0, never NaN.
#[inline]
pub fn triangle_solid_angle(q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let a = a - q;
    let b = b - q;
    let c = c - q;
    let la = a.length();
    let lb = b.length();
    let lc = c.length();
    let numerator = a.dot(b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    2.0 * numerator.atan2(denominator)
}

/// Exact generalized winding number of the soup `(positions, triangles)` at `p`: the sum of the
/// triangles' signed solid angles over `4π`. O(#triangles); the oracle for [`WindingNumber`].
///
/// Triangles with out-of-range indices are ignored (this function never panics); use
/// [`check_triangle_indices`] first to refuse such input.
pub fn exact_winding_number(positions: &[DVec3], triangles: &[[u32; 3]], p: DVec3) -> f64 {
    let n = positions.len();
    let mut total = 0.0;
    for tri in triangles {
        if tri.iter().any(|&v| v as usize >= n) {
            continue;
        }
        total += triangle_solid_angle(
            p,
            positions[tri[0] as usize],
            positions[tri[1] as usize],
            positions[tri[2] as usize],
        );
    }
    total / (4.0 * PI)
}

/// Options of the fast winding number (Barill et al. 2018).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindingNumberOptions {
    /// Accuracy parameter β: a node is evaluated by its expansion when the query is farther than
    /// `β × radius` from the node's expansion centre. Larger is more accurate and slower.
    /// Default 2, as in Barill et al. 2018.
    pub beta: f64,
    /// Maximum number of triangles per leaf of the hierarchy. Default 8.
    pub leaf_size: usize,
}

impl Default for WindingNumberOptions {
    fn default() -> Self {
        Self {
            beta: 2.0,
            leaf_size: 8,
        }
    }
}

/// One node of the hierarchy: its triangles are `order[start..end]`, stored contiguously in
/// `WindingNumber::corners`.
#[derive(Debug, Clone)]
struct Node {
    /// Expansion centre: area-weighted centroid of the node's triangles.
    center: DVec3,
    /// Squared far-field threshold `(β × radius)²`, radius = farthest triangle corner from `center`.
    far_distance_sq: f64,
    /// Order-1 coefficient: Σ area·unit normal = Σ ½ (b−a)×(c−a).
    normal_sum: DVec3,
    /// Order-2 coefficient: Σ area · n ⊗ (centroid − center), row i = n_i.
    second: [DVec3; 3],
    /// Order-3 coefficient: `third[i]` = Σ n_i ∫ u uᵀ dA (symmetric), u = x − center.
    third: [DMat3; 3],
    start: u32,
    end: u32,
    /// Index of the second child (the first is `self + 1`); 0 for a leaf.
    right: u32,
}

/// The part of a node the traversal reads for every visited node, kept apart from the (large)
/// expansion coefficients so the traversal stays in cache.
#[derive(Debug, Clone, Copy)]
struct NodeBounds {
    center: DVec3,
    far_distance_sq: f64,
    start: u32,
    end: u32,
    right: u32,
}

/// Fast generalized winding number of a fixed triangle soup (Barill et al. 2018), with the
/// dipole far-field expansion carried to the kernel's second derivative.
///
/// Build once with [`WindingNumber::build`], then query single points with
/// [`WindingNumber::winding_number`] or many with [`WindingNumber::winding_numbers`] (parallel,
/// deterministic). Accuracy with the default β = 2 against [`exact_winding_number`] on an
/// 82k-triangle sphere: mean 1e-3, max 5e-3 absolute (β = 3: mean 2e-4 to 4e-4, max 1e-3, at
/// about twice the cost).
#[derive(Debug, Clone)]
pub struct WindingNumber {
    bounds: Vec<NodeBounds>,
    /// Full nodes (expansion coefficients), same indexing as `bounds`.
    nodes: Vec<Node>,
    /// Triangle corners in hierarchy order.
    corners: Vec<[DVec3; 3]>,
}

impl WindingNumber {
    /// Builds the hierarchy with default options (β = 2).
    ///
    /// Fails when a triangle refers to a missing vertex. Degenerate (zero-area) triangles are
    /// fine: they contribute nothing.
    pub fn build(positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<Self, TriangleIndexError> {
        Self::build_with(positions, triangles, &WindingNumberOptions::default())
    }

    /// Builds the hierarchy with explicit options. See [`WindingNumber::build`].
    pub fn build_with(
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        options: &WindingNumberOptions,
    ) -> Result<Self, TriangleIndexError> {
        check_triangle_indices(positions.len(), triangles)?;
        let mut corners: Vec<[DVec3; 3]> = triangles
            .iter()
            .map(|t| {
                [
                    positions[t[0] as usize],
                    positions[t[1] as usize],
                    positions[t[2] as usize],
                ]
            })
            .collect();
        let mut centroids: Vec<DVec3> =
            corners.iter().map(|c| (c[0] + c[1] + c[2]) / 3.0).collect();
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len() / options.leaf_size.max(1) + 1);
        if !triangles.is_empty() {
            let leaf_size = options.leaf_size.max(1);
            build_node(&mut nodes, &mut order, &centroids, 0, leaf_size);
        }
        // Reorder corners into hierarchy order so leaves read contiguous memory.
        corners = order.iter().map(|&t| corners[t as usize]).collect();
        centroids = order.iter().map(|&t| centroids[t as usize]).collect();
        let beta = if options.beta.is_finite() && options.beta > 0.0 {
            options.beta
        } else {
            WindingNumberOptions::default().beta
        };
        for node in &mut nodes {
            fill_expansion(node, &corners, &centroids, beta);
        }
        let bounds = nodes
            .iter()
            .map(|n| NodeBounds {
                center: n.center,
                far_distance_sq: n.far_distance_sq,
                start: n.start,
                end: n.end,
                right: n.right,
            })
            .collect();
        Ok(Self {
            bounds,
            nodes,
            corners,
        })
    }

    /// Number of triangles in the soup.
    pub fn triangle_count(&self) -> usize {
        self.corners.len()
    }

    /// Winding number at `p`: ~1 inside and ~0 outside a closed outward-oriented mesh.
    /// Deterministic; NaN only if `p` or the positions are not finite.
    pub fn winding_number(&self, p: DVec3) -> f64 {
        if self.nodes.is_empty() {
            return 0.0;
        }
        let mut total = 0.0;
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(index) = stack.pop() {
            let node = &self.bounds[index as usize];
            let r = node.center - p;
            let d2 = r.length_squared();
            if d2 > node.far_distance_sq {
                total += far_field(&self.nodes[index as usize], r, d2);
            } else if node.right == 0 {
                for c in &self.corners[node.start as usize..node.end as usize] {
                    total += triangle_solid_angle(p, c[0], c[1], c[2]);
                }
            } else {
                // Push right first so the left subtree is evaluated first (fixed order).
                stack.push(node.right);
                stack.push(index + 1);
            }
        }
        total / (4.0 * PI)
    }

    /// Winding numbers of many points, in the same order, computed in parallel over coarse
    /// chunks. Each value is computed independently, so the result is bit-identical to calling
    /// [`WindingNumber::winding_number`] point by point, whatever the thread count.
    pub fn winding_numbers(&self, points: &[DVec3]) -> Vec<f64> {
        const CHUNK: usize = 1024;
        if points.len() <= CHUNK {
            return points.iter().map(|&p| self.winding_number(p)).collect();
        }
        // Visit the points in Morton order so consecutive queries walk the same part of the
        // tree (cache locality); values are independent of the visiting order.
        let order = morton_order(points);
        let sorted: Vec<f64> = order
            .par_iter()
            .with_min_len(CHUNK)
            .map(|&i| self.winding_number(points[i as usize]))
            .collect();
        let mut values = vec![0.0; points.len()];
        for (&i, &w) in order.iter().zip(&sorted) {
            values[i as usize] = w;
        }
        values
    }
}

/// Indices of `points` sorted by the Morton code of their position in the points' bounding box
/// (non-finite points first); a stable sort, so the order is deterministic. Batched tree queries
/// visit points in this order so that consecutive queries walk the same part of the tree.
pub fn morton_order(points: &[DVec3]) -> Vec<u32> {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in points.iter().filter(|p| p.is_finite()) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let scale = (hi - lo).max_element();
    let scale = if scale > 0.0 { 1023.0 / scale } else { 0.0 };
    let spread = |v: u64| {
        // Spread the 10 low bits of v so there are two zero bits between each.
        let mut x = v & 0x3ff;
        x = (x | (x << 16)) & 0x0300_00ff;
        x = (x | (x << 8)) & 0x0300_f00f;
        x = (x | (x << 4)) & 0x030c_30c3;
        (x | (x << 2)) & 0x0924_9249
    };
    let key = |p: &DVec3| -> u64 {
        if !p.is_finite() {
            return 0;
        }
        let c = ((*p - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(1023.0));
        spread(c.x as u64) | (spread(c.y as u64) << 1) | (spread(c.z as u64) << 2)
    };
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_by_cached_key(|&i| key(&points[i as usize]));
    order
}

/// Far-field evaluation of one node: 4π × (its winding number contribution), from the Taylor
/// expansion of the dipole kernel `(x−q)/|x−q|³` about the node centre. `r = center − q`.
#[inline]
fn far_field(node: &Node, r: DVec3, d2: f64) -> f64 {
    let d = d2.sqrt();
    let inv_d3 = 1.0 / (d2 * d);
    let inv_d5 = inv_d3 / d2;
    // Order 1: f(center)·N with f = r/|r|³.
    let order1 = r.dot(node.normal_sum) * inv_d3;
    // Order 2: J : M with J = I/d³ − 3 r rᵀ/d⁵ (the Jacobian of f, symmetric), M_ij = Σ a n_i u_j.
    let m = &node.second;
    let trace = m[0].x + m[1].y + m[2].z;
    let r_m_r = r.x * m[0].dot(r) + r.y * m[1].dot(r) + r.z * m[2].dot(r);
    let order2 = trace * inv_d3 - 3.0 * r_m_r * inv_d5;
    // Order 3: ½ H : T with H_ijk = ∂²f_i/∂x_j∂x_k
    //   = −3(δ_ij r_k + δ_ik r_j + δ_jk r_i)/d⁵ + 15 r_i r_j r_k/d⁷,
    // T_ijk = Σ ∫ n_i u_j u_k dA (node.third[i] is the symmetric matrix T_i··).
    let t = &node.third;
    let diagonal_rows = t[0].col(0).dot(r) + t[1].col(1).dot(r) + t[2].col(2).dot(r);
    let traces = r.x * mat_trace(&t[0]) + r.y * mat_trace(&t[1]) + r.z * mat_trace(&t[2]);
    let cubic = r.x * r.dot(t[0] * r) + r.y * r.dot(t[1] * r) + r.z * r.dot(t[2] * r);
    let order3 =
        0.5 * (-3.0 * (2.0 * diagonal_rows + traces) * inv_d5 + 15.0 * cubic * inv_d5 / d2);
    order1 + order2 + order3
}

#[inline]
fn mat_trace(m: &DMat3) -> f64 {
    m.x_axis.x + m.y_axis.y + m.z_axis.z
}

/// Builds the subtree over `order[start..start+len]` (indices relative to the whole `order`),
/// splitting at the median centroid along the longest axis of the centroids' bounding box.
/// Returns the node index.
fn build_node(
    nodes: &mut Vec<Node>,
    order: &mut [u32],
    centroids: &[DVec3],
    offset: usize,
    leaf_size: usize,
) -> u32 {
    let index = nodes.len() as u32;
    nodes.push(Node {
        center: DVec3::ZERO,
        far_distance_sq: 0.0,
        normal_sum: DVec3::ZERO,
        second: [DVec3::ZERO; 3],
        third: [DMat3::ZERO; 3],
        start: offset as u32,
        end: (offset + order.len()) as u32,
        right: 0,
    });
    if order.len() <= leaf_size {
        return index;
    }
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &t in order.iter() {
        let c = centroids[t as usize];
        lo = lo.min(c);
        hi = hi.max(c);
    }
    let extent = hi - lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis]
            .total_cmp(&centroids[b as usize][axis])
            .then(a.cmp(&b))
    });
    let (left, right) = order.split_at_mut(mid);
    build_node(nodes, left, centroids, offset, leaf_size);
    let right_index = build_node(nodes, right, centroids, offset + mid, leaf_size);
    nodes[index as usize].right = right_index;
    index
}

/// Computes the expansion centre, radius and coefficients of `node` from its triangles.
fn fill_expansion(node: &mut Node, corners: &[[DVec3; 3]], centroids: &[DVec3], beta: f64) {
    let range = node.start as usize..node.end as usize;
    let mut area_sum = 0.0;
    let mut weighted = DVec3::ZERO;
    let mut normal_sum = DVec3::ZERO;
    for (c, &g) in corners[range.clone()].iter().zip(&centroids[range.clone()]) {
        let an = 0.5 * (c[1] - c[0]).cross(c[2] - c[0]);
        let area = an.length();
        area_sum += area;
        weighted += area * g;
        normal_sum += an;
    }
    let center = if area_sum > 0.0 && weighted.is_finite() {
        weighted / area_sum
    } else {
        centroids[range.clone()].iter().copied().sum::<DVec3>() / range.len() as f64
    };
    let mut second = [DVec3::ZERO; 3];
    let mut third = [DMat3::ZERO; 3];
    let mut radius_sq: f64 = 0.0;
    for (c, &g) in corners[range.clone()].iter().zip(&centroids[range.clone()]) {
        let an = 0.5 * (c[1] - c[0]).cross(c[2] - c[0]);
        let u = g - center;
        second[0] += an.x * u;
        second[1] += an.y * u;
        second[2] += an.z * u;
        // ∫_t u uᵀ dA / area = u_g u_gᵀ + (1/12) Σ_k (v_k − g)(v_k − g)ᵀ (exact for a triangle).
        let mut moment = DMat3::from_cols(u * u.x, u * u.y, u * u.z);
        for v in c {
            let e = *v - g;
            moment += DMat3::from_cols(e * e.x, e * e.y, e * e.z) * (1.0 / 12.0);
        }
        third[0] += moment * an.x;
        third[1] += moment * an.y;
        third[2] += moment * an.z;
        for v in c {
            radius_sq = radius_sq.max(v.distance_squared(center));
        }
    }
    node.center = center;
    node.normal_sum = normal_sum;
    node.second = second;
    node.third = third;
    // NaN (non-finite input) compares false in `d2 > far`, so such nodes are always opened.
    node.far_distance_sq = beta * beta * radius_sq;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        // Outward orientation.
        let t = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        (p, t)
    }

    #[test]
    fn solid_angle_is_positive_behind_triangle_and_on_plane_is_zero() {
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(1.0, 0.0, 0.0);
        let c = DVec3::new(0.0, 1.0, 0.0);
        // Normal is +z; a point below sees the back side.
        assert!(triangle_solid_angle(DVec3::new(0.2, 0.2, -0.1), a, b, c) > 0.0);
        assert!(triangle_solid_angle(DVec3::new(0.2, 0.2, 0.1), a, b, c) < 0.0);
        assert_eq!(triangle_solid_angle(a, a, b, c), 0.0);
    }

    #[test]
    fn exact_tetrahedron_inside_is_one_outside_is_zero() {
        let (p, t) = tetrahedron();
        let inside = exact_winding_number(&p, &t, DVec3::splat(0.1));
        let outside = exact_winding_number(&p, &t, DVec3::splat(2.0));
        assert!((inside - 1.0).abs() < 1e-12, "{inside}");
        assert!(outside.abs() < 1e-12, "{outside}");
    }

    #[test]
    fn far_field_matches_exact_far_away() {
        let (p, t) = tetrahedron();
        let wn = WindingNumber::build_with(
            &p,
            &t,
            &WindingNumberOptions {
                beta: 2.0,
                leaf_size: 1,
            },
        )
        .unwrap();
        let q = DVec3::new(3.0, -2.0, 1.5);
        assert!((wn.winding_number(q) - exact_winding_number(&p, &t, q)).abs() < 1e-3);
    }

    #[test]
    fn far_field_error_decays_like_the_fifth_power_of_distance() {
        // A bumpy open patch evaluated by its root expansion only: with three terms the
        // truncation error is O(d⁻⁵), so doubling the distance divides it by about 32.
        let mut p = Vec::new();
        let mut t = Vec::new();
        for j in 0..4u32 {
            for i in 0..4u32 {
                let x = i as f64 * 0.25;
                let y = j as f64 * 0.25;
                p.push(DVec3::new(x, y, 0.3 * (3.0 * x).sin() * (2.0 * y).cos()));
            }
        }
        for j in 0..3u32 {
            for i in 0..3u32 {
                let v = j * 4 + i;
                t.push([v, v + 1, v + 5]);
                t.push([v, v + 5, v + 4]);
            }
        }
        let options = WindingNumberOptions {
            beta: 1.0,
            leaf_size: 1000,
        };
        let wn = WindingNumber::build_with(&p, &t, &options).unwrap();
        let dir = DVec3::new(0.3, 0.2, 1.0).normalize();
        let error = |d: f64| {
            let q = DVec3::new(0.4, 0.4, 0.0) + d * dir;
            (wn.winding_number(q) - exact_winding_number(&p, &t, q)).abs()
        };
        let (e1, e2, e3) = (error(8.0), error(16.0), error(32.0));
        assert!(e1 / e2 > 20.0 && e2 / e3 > 20.0, "{e1:e} {e2:e} {e3:e}");
    }

    #[test]
    fn out_of_range_index_is_an_error() {
        let p = vec![DVec3::ZERO; 3];
        let err = WindingNumber::build(&p, &[[0, 1, 3]]).unwrap_err();
        assert_eq!(err.triangle, 0);
        assert_eq!(err.vertex, 3);
    }

    #[test]
    fn empty_soup_has_zero_winding_number() {
        let wn = WindingNumber::build(&[], &[]).unwrap();
        assert_eq!(wn.winding_number(DVec3::ZERO), 0.0);
    }
}
