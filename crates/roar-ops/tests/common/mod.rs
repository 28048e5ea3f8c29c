//! Test support: where the shared test meshes live, soups and a closed-manifold checker.
#![allow(dead_code)]

use glam::DVec3;
use std::collections::HashMap;
use std::path::PathBuf;

/// A triangle soup.
pub struct Soup {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// The data folder, or `None` (test passes with a note) when `ROAR_TEST_DATA` is unset outside CI.
pub fn data_dir() -> Option<PathBuf> {
    match std::env::var("ROAR_TEST_DATA") {
        Ok(dir) => {
            let dir = PathBuf::from(dir);
            assert!(
                dir.join("clean").is_dir() && dir.join("wild").is_dir(),
                "ROAR_TEST_DATA={} has no clean/ and wild/",
                dir.display()
            );
            Some(dir)
        }
        Err(_) => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "ROAR_TEST_DATA must be set in CI"
            );
            eprintln!("note: ROAR_TEST_DATA unset; skipping real-data test");
            None
        }
    }
}

/// Facts about a closed, consistently oriented 2-manifold.
#[derive(Debug)]
pub struct ManifoldReport {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub components: usize,
    pub euler: i64,
    pub volume: f64,
}

/// Checks: every undirected edge used by exactly two faces in opposite directions, no degenerate
/// index triple, no unreferenced vertex, every vertex's faces form one fan, positive signed volume
/// of every component. Returns the report or a description of the first failure.
pub fn check_closed_manifold(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Result<ManifoldReport, String> {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(format!("face {f} repeats a vertex"));
        }
        for k in 0..3 {
            let e = (t[k], t[(k + 1) % 3]);
            if directed.insert(e, f).is_some() {
                return Err(format!(
                    "directed edge {e:?} used twice (non-manifold or flipped)"
                ));
            }
        }
    }
    for &(a, b) in directed.keys() {
        if !directed.contains_key(&(b, a)) {
            return Err(format!("edge ({a}, {b}) is a boundary edge"));
        }
    }
    // One fan per vertex: follow (v, a) -> (v, b) around each vertex.
    let mut out_next: HashMap<(u32, u32), u32> = HashMap::new();
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
    for t in triangles {
        for k in 0..3 {
            let (v, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            out_next.insert((v, a), b);
            incident[v as usize].push(a);
        }
    }
    for (v, starts) in incident.iter().enumerate() {
        if starts.is_empty() {
            return Err(format!("vertex {v} is unreferenced"));
        }
        let first = starts[0];
        let mut cur = first;
        let mut steps = 0;
        loop {
            // The face after (v, cur, next) around v is the one with directed edge (v, next).
            cur = out_next[&(v as u32, cur)];
            steps += 1;
            if cur == first || steps > starts.len() {
                break;
            }
        }
        if steps != starts.len() {
            return Err(format!(
                "vertex {v} has {} faces but its first fan has {steps}",
                starts.len()
            ));
        }
    }
    // Components and volumes.
    let mut parent: Vec<usize> = (0..positions.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for t in triangles {
        let a = find(&mut parent, t[0] as usize);
        for &v in &t[1..] {
            let b = find(&mut parent, v as usize);
            parent[b] = a;
        }
    }
    let mut volume: HashMap<usize, f64> = HashMap::new();
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        *volume.entry(find(&mut parent, t[0] as usize)).or_default() +=
            p[0].dot(p[1].cross(p[2])) / 6.0;
    }
    if let Some((_, v)) = volume.iter().find(|(_, v)| **v <= 0.0) {
        return Err(format!("a component has non-positive volume {v}"));
    }
    let edges = directed.len() / 2;
    Ok(ManifoldReport {
        vertices: positions.len(),
        edges,
        faces: triangles.len(),
        components: volume.len(),
        euler: positions.len() as i64 - edges as i64 + triangles.len() as i64,
        volume: volume.values().sum(),
    })
}

fn separated_on(axis: DVec3, a: &[DVec3; 3], b: &[DVec3; 3], eps: f64) -> bool {
    if axis.length_squared() < 1e-24 {
        return false;
    }
    let axis = axis.normalize();
    let pa = a.map(|p| p.dot(axis));
    let pb = b.map(|p| p.dot(axis));
    let (amin, amax) = (pa[0].min(pa[1]).min(pa[2]), pa[0].max(pa[1]).max(pa[2]));
    let (bmin, bmax) = (pb[0].min(pb[1]).min(pb[2]), pb[0].max(pb[1]).max(pb[2]));
    amax < bmin - eps || bmax < amin - eps
}

/// Whether two triangles sharing no vertex touch (separating axis test, exact enough for tests).
pub fn triangles_intersect(a: &[DVec3; 3], b: &[DVec3; 3], eps: f64) -> bool {
    let ea = [a[1] - a[0], a[2] - a[1], a[0] - a[2]];
    let eb = [b[1] - b[0], b[2] - b[1], b[0] - b[2]];
    let na = ea[0].cross(ea[1]);
    let nb = eb[0].cross(eb[1]);
    let mut axes = vec![na, nb];
    for x in ea {
        for y in eb {
            axes.push(x.cross(y));
        }
        axes.push(na.cross(x));
    }
    for y in eb {
        axes.push(nb.cross(y));
    }
    !axes.into_iter().any(|ax| separated_on(ax, a, b, eps))
}

/// Whether the open segment p–q crosses the triangle (used for triangles sharing one vertex).
fn segment_hits_triangle(p: DVec3, q: DVec3, t: &[DVec3; 3], eps: f64) -> bool {
    let d = q - p;
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-18 {
        return false;
    }
    let s = p - t[0];
    let u = s.dot(h) / det;
    let qv = s.cross(e1);
    let v = d.dot(qv) / det;
    let w = e2.dot(qv) / det;
    u > eps && v > eps && u + v < 1.0 - eps && w > eps && w < 1.0 - eps
}

/// Counts intersecting triangle pairs by brute force (with an AABB pre-filter). Pairs sharing an
/// edge are skipped; pairs sharing one vertex are tested for an edge crossing the other triangle.
pub fn count_self_intersections(positions: &[DVec3], triangles: &[[u32; 3]]) -> usize {
    let tris: Vec<[DVec3; 3]> = triangles
        .iter()
        .map(|t| t.map(|i| positions[i as usize]))
        .collect();
    let boxes: Vec<(DVec3, DVec3)> = tris
        .iter()
        .map(|t| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])))
        .collect();
    let scale = boxes
        .iter()
        .map(|b| (b.1 - b.0).max_element())
        .fold(0.0, f64::max);
    let eps = 1e-9 * scale;
    let mut order: Vec<usize> = (0..tris.len()).collect();
    order.sort_by(|&i, &j| boxes[i].0.x.total_cmp(&boxes[j].0.x));
    let mut count = 0;
    for (oi, &i) in order.iter().enumerate() {
        for &j in &order[oi + 1..] {
            if boxes[j].0.x > boxes[i].1.x + eps {
                break;
            }
            let (a, b) = (&boxes[i], &boxes[j]);
            if (0..3).any(|k| a.1[k] < b.0[k] - eps || b.1[k] < a.0[k] - eps) {
                continue;
            }
            let shared: Vec<u32> = triangles[i]
                .iter()
                .copied()
                .filter(|v| triangles[j].contains(v))
                .collect();
            let hit = match shared.len() {
                0 => triangles_intersect(&tris[i], &tris[j], eps),
                1 => {
                    let opp = |t: &[u32; 3], p: &[DVec3; 3]| {
                        let k = t.iter().position(|v| *v == shared[0]).unwrap();
                        (p[(k + 1) % 3], p[(k + 2) % 3])
                    };
                    let (p, q) = opp(&triangles[i], &tris[i]);
                    let (r, s) = opp(&triangles[j], &tris[j]);
                    segment_hits_triangle(p, q, &tris[j], 1e-9)
                        || segment_hits_triangle(r, s, &tris[i], 1e-9)
                }
                _ => false,
            };
            if hit {
                count += 1;
            }
        }
    }
    count
}

/// An axis-aligned box soup (12 triangles, outward) from `min` to `max`.
pub fn box_soup(min: DVec3, max: DVec3) -> Soup {
    let mut positions = Vec::new();
    for k in 0..8 {
        positions.push(DVec3::new(
            if k & 1 == 0 { min.x } else { max.x },
            if k & 2 == 0 { min.y } else { max.y },
            if k & 4 == 0 { min.z } else { max.z },
        ));
    }
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut triangles = Vec::new();
    for q in quads {
        triangles.push([q[0], q[1], q[2]]);
        triangles.push([q[0], q[2], q[3]]);
    }
    Soup {
        positions,
        triangles,
    }
}

/// Appends `other` to `soup`.
pub fn append(soup: &mut Soup, other: &Soup) {
    let base = soup.positions.len() as u32;
    soup.positions.extend_from_slice(&other.positions);
    soup.triangles
        .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
}

/// Debug helper: the first few intersecting pairs (indices) by the same test.
pub fn first_intersections(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    limit: usize,
) -> Vec<(usize, usize)> {
    let mut found = Vec::new();
    for i in 0..triangles.len() {
        for j in i + 1..triangles.len() {
            if count_self_intersections(positions, &[triangles[i], triangles[j]]) > 0 {
                found.push((i, j));
                if found.len() == limit {
                    return found;
                }
            }
        }
    }
    found
}
