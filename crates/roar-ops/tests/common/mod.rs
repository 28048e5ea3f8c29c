//! Test support: a minimal mesh loader (OBJ, OFF, STL, PLY) and a closed-manifold checker.
#![allow(dead_code)]

use glam::DVec3;
use std::collections::HashMap;
use std::path::Path;

/// A loaded triangle soup.
pub struct Soup {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

fn fan(poly: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..poly.len().saturating_sub(1) {
        out.push([poly[0], poly[k], poly[k + 1]]);
    }
}

/// Loads OBJ / OFF / STL (ASCII or binary) / PLY (ASCII or binary little-endian), by extension.
pub fn load(path: &Path) -> Soup {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let ext = path.extension().unwrap().to_string_lossy().to_lowercase();
    match ext.as_str() {
        "obj" => load_obj(&String::from_utf8_lossy(&bytes)),
        "off" => load_off(&String::from_utf8_lossy(&bytes)),
        "stl" => load_stl(&bytes),
        "ply" => load_ply(&bytes),
        _ => panic!("unknown extension {ext}"),
    }
}

fn load_obj(text: &str) -> Soup {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).map(|x| x.parse().unwrap()).collect();
                positions.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let n = positions.len() as i64;
                let poly: Vec<u32> = it
                    .map(|w| {
                        let i: i64 = w.split('/').next().unwrap().parse().unwrap();
                        (if i < 0 { n + i } else { i - 1 }) as u32
                    })
                    .collect();
                fan(&poly, &mut triangles);
            }
            _ => {}
        }
    }
    Soup {
        positions,
        triangles,
    }
}

fn load_off(text: &str) -> Soup {
    let mut words = text
        .lines()
        .map(|l| l.split('#').next().unwrap())
        .flat_map(|l| l.split_whitespace());
    let head = words.next().unwrap();
    assert!(head.ends_with("OFF"));
    let nv: usize = words.next().unwrap().parse().unwrap();
    let nf: usize = words.next().unwrap().parse().unwrap();
    let _ne = words.next();
    let mut positions = Vec::with_capacity(nv);
    for _ in 0..nv {
        let c: Vec<f64> = (0..3)
            .map(|_| words.next().unwrap().parse().unwrap())
            .collect();
        positions.push(DVec3::new(c[0], c[1], c[2]));
    }
    let mut triangles = Vec::new();
    for _ in 0..nf {
        let k: usize = words.next().unwrap().parse().unwrap();
        let poly: Vec<u32> = (0..k)
            .map(|_| words.next().unwrap().parse().unwrap())
            .collect();
        fan(&poly, &mut triangles);
    }
    Soup {
        positions,
        triangles,
    }
}

fn f32_at(b: &[u8], o: usize) -> f64 {
    f32::from_le_bytes(b[o..o + 4].try_into().unwrap()) as f64
}

fn load_stl(bytes: &[u8]) -> Soup {
    let mut positions = Vec::new();
    let binary = bytes.len() >= 84 && {
        let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
        84 + 50 * n == bytes.len()
    };
    if binary {
        let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
        for f in 0..n {
            let o = 84 + 50 * f + 12;
            for v in 0..3 {
                let p = o + 12 * v;
                positions.push(DVec3::new(
                    f32_at(bytes, p),
                    f32_at(bytes, p + 4),
                    f32_at(bytes, p + 8),
                ));
            }
        }
    } else {
        for line in String::from_utf8_lossy(bytes).lines() {
            let mut it = line.split_whitespace();
            if it.next() == Some("vertex") {
                let c: Vec<f64> = it.take(3).map(|x| x.parse().unwrap()).collect();
                positions.push(DVec3::new(c[0], c[1], c[2]));
            }
        }
    }
    let triangles = (0..positions.len() as u32 / 3)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    Soup {
        positions,
        triangles,
    }
}

/// A PLY element: name, count, properties as (type, list count type, name).
type PlyElement = (String, usize, Vec<(String, Option<String>, String)>);

fn load_ply(bytes: &[u8]) -> Soup {
    let end = bytes.windows(10).position(|w| w == b"end_header").unwrap();
    let header = String::from_utf8_lossy(&bytes[..end]).to_string();
    let mut body = end + 10;
    while bytes[body] != b'\n' {
        body += 1;
    }
    body += 1;
    let binary = header.contains("binary_little_endian");
    // Elements: (name, count, properties as (type, list count type or None, name)).
    let mut elements: Vec<PlyElement> = Vec::new();
    for line in header.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"element") => {
                elements.push((w[1].to_string(), w[2].parse().unwrap(), Vec::new()))
            }
            Some(&"property") if w[1] == "list" => elements.last_mut().unwrap().2.push((
                w[3].to_string(),
                Some(w[2].to_string()),
                w[4].to_string(),
            )),
            Some(&"property") => {
                elements
                    .last_mut()
                    .unwrap()
                    .2
                    .push((w[1].to_string(), None, w[2].to_string()))
            }
            _ => {}
        }
    }
    let size = |t: &str| match t {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        _ => panic!("ply type {t}"),
    };
    let read_bin = |t: &str, b: &[u8]| -> f64 {
        match t {
            "char" | "int8" => b[0] as i8 as f64,
            "uchar" | "uint8" => b[0] as f64,
            "short" | "int16" => i16::from_le_bytes([b[0], b[1]]) as f64,
            "ushort" | "uint16" => u16::from_le_bytes([b[0], b[1]]) as f64,
            "int" | "int32" => i32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            "uint" | "uint32" => u32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            "float" | "float32" => f32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            _ => f64::from_le_bytes(b[..8].try_into().unwrap()),
        }
    };
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let text = String::from_utf8_lossy(&bytes[body..]).to_string();
    let mut words = text.split_whitespace();
    let mut offset = body;
    for (name, count, props) in &elements {
        for _ in 0..*count {
            let mut xyz = [0.0; 3];
            let mut poly = Vec::new();
            for (t, list, pname) in props {
                let mut next = |t: &str| -> f64 {
                    if binary {
                        let v = read_bin(t, &bytes[offset..]);
                        offset += size(t);
                        v
                    } else {
                        words.next().unwrap().parse().unwrap()
                    }
                };
                if let Some(ct) = list {
                    let k = next(ct) as usize;
                    let vals: Vec<u32> = (0..k).map(|_| next(t) as u32).collect();
                    if pname == "vertex_indices" || pname == "vertex_index" {
                        poly = vals;
                    }
                } else {
                    let v = next(t);
                    match pname.as_str() {
                        "x" => xyz[0] = v,
                        "y" => xyz[1] = v,
                        "z" => xyz[2] = v,
                        _ => {}
                    }
                }
            }
            if name == "vertex" {
                positions.push(DVec3::from(xyz));
            } else if name == "face" {
                fan(&poly, &mut triangles);
            }
        }
    }
    Soup {
        positions,
        triangles,
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
