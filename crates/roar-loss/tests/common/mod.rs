//! Test support for roar-loss: procedural shapes, random numbers and where the real meshes live.
#![allow(dead_code)]

use glam::DVec3;
use std::collections::HashMap;
use std::path::PathBuf;

/// Axis-aligned cube of half-size `h` centred at `c`: 8 corners, 12 outward (CCW) triangles.
pub fn cube(c: DVec3, h: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let p = (0..8)
        .map(|i| c + h * DVec3::new(sign(i & 1), sign(i & 2), sign(i & 4)))
        .collect();
    // Corner i has x = +h iff bit 0, y iff bit 1, z iff bit 2.
    let quads = [
        [0, 2, 3, 1], // z−
        [4, 5, 7, 6], // z+
        [0, 1, 5, 4], // y−
        [2, 6, 7, 3], // y+
        [0, 4, 6, 2], // x−
        [1, 3, 7, 5], // x+
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (p, t)
}

fn sign(bit: usize) -> f64 {
    if bit != 0 { 1.0 } else { -1.0 }
}

/// Appends mesh `b` to mesh `a` (indices shifted).
pub fn append(a: &mut (Vec<DVec3>, Vec<[u32; 3]>), b: (Vec<DVec3>, Vec<[u32; 3]>)) {
    let offset = a.0.len() as u32;
    a.0.extend(b.0);
    a.1.extend(b.1.iter().map(|t| t.map(|i| i + offset)));
}

/// Unit sphere from an octahedron with `levels` midpoint subdivisions (8·4^levels faces),
/// outward CCW, scaled by `radius`.
pub fn sphere(levels: u32, radius: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut p = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let mut t: Vec<[u32; 3]> = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    for _ in 0..levels {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(t.len() * 4);
        for &[a, b, c] in &t {
            let mut m = |i: u32, j: u32| {
                *mid.entry((i.min(j), i.max(j))).or_insert_with(|| {
                    p.push((p[i as usize] + p[j as usize]).normalize());
                    (p.len() - 1) as u32
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        t = next;
    }
    (p.into_iter().map(|v| v * radius).collect(), t)
}

/// Reverses every face.
pub fn reversed(t: &[[u32; 3]]) -> Vec<[u32; 3]> {
    t.iter().map(|&[a, b, c]| [a, c, b]).collect()
}

/// Tiny deterministic generator for test directions.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn vec3(&mut self) -> DVec3 {
        DVec3::new(self.unit() - 0.5, self.unit() - 0.5, self.unit() - 0.5) * 2.0
    }
}

/// The `wild` mesh folder, or `None` (with a note) when `ROAR_TEST_DATA` is unset outside CI.
pub fn wild_dir() -> Option<PathBuf> {
    match std::env::var("ROAR_TEST_DATA") {
        Ok(root) => {
            let dir = PathBuf::from(root).join("wild");
            assert!(
                dir.is_dir(),
                "ROAR_TEST_DATA names a missing folder: {dir:?}"
            );
            Some(dir)
        }
        Err(_) => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "CI=true needs ROAR_TEST_DATA"
            );
            eprintln!("note: ROAR_TEST_DATA is unset; skipping the real-data test");
            None
        }
    }
}

/// CPU seconds (user + system) used by this process so far, from `/proc/self/stat` (Linux;
/// NaN elsewhere). Timings on a loaded machine read better in CPU time than in wall time.
pub fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')').map_or(0, |i| i + 2)..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| fields.get(k - 3).and_then(|f| f.parse::<f64>().ok());
    match (ticks(14), ticks(15)) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
}
