//! Test-only mesh loader (OBJ, OFF, STL, PLY; to be replaced by roar-io) and procedural shapes.
#![allow(dead_code)]

use glam::DVec3;
use std::path::{Path, PathBuf};

pub mod shapes;

/// A loaded soup: positions as stored, polygons fan-triangulated.
pub struct Soup {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// Faces with more than three corners in the file.
    pub polygons: usize,
}

/// Folder of the shared test meshes, or `None` (with a note) when `ROAR_TEST_DATA` is unset
/// outside CI. Panics when CI requires it or the folder is missing.
pub fn test_data() -> Option<PathBuf> {
    match std::env::var_os("ROAR_TEST_DATA") {
        Some(p) => {
            let p = PathBuf::from(p);
            assert!(
                p.is_dir(),
                "ROAR_TEST_DATA names a missing folder: {}",
                p.display()
            );
            Some(p)
        }
        None if std::env::var("CI").as_deref() == Ok("true") => {
            panic!("ROAR_TEST_DATA must be set when CI=true")
        }
        None => {
            eprintln!("note: ROAR_TEST_DATA unset; skipping real-data test");
            None
        }
    }
}

fn fan(poly: &[u32], out: &mut Soup) {
    if poly.len() > 3 {
        out.polygons += 1;
    }
    for k in 1..poly.len().saturating_sub(1) {
        out.triangles.push([poly[0], poly[k], poly[k + 1]]);
    }
}

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

fn empty() -> Soup {
    Soup {
        positions: Vec::new(),
        triangles: Vec::new(),
        polygons: 0,
    }
}

fn load_obj(text: &str) -> Soup {
    let mut s = empty();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).map(|x| x.parse().unwrap()).collect();
                s.positions.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let n = s.positions.len() as i64;
                let poly: Vec<u32> = it
                    .map(|tok| {
                        let i: i64 = tok.split('/').next().unwrap().parse().unwrap();
                        (if i < 0 { n + i } else { i - 1 }) as u32
                    })
                    .collect();
                fan(&poly, &mut s);
            }
            _ => {}
        }
    }
    s
}

fn load_off(text: &str) -> Soup {
    let mut tokens = text
        .lines()
        .map(|l| l.split('#').next().unwrap())
        .flat_map(str::split_whitespace);
    let head = tokens.next().unwrap();
    assert!(head.ends_with("OFF"), "not OFF");
    let mut num = || tokens.next().unwrap();
    let nv: usize = num().parse().unwrap();
    let nf: usize = num().parse().unwrap();
    let _ne = num();
    let mut s = empty();
    for _ in 0..nv {
        let c: Vec<f64> = (0..3).map(|_| num().parse().unwrap()).collect();
        s.positions.push(DVec3::new(c[0], c[1], c[2]));
    }
    for _ in 0..nf {
        let k: usize = num().parse().unwrap();
        let poly: Vec<u32> = (0..k).map(|_| num().parse().unwrap()).collect();
        fan(&poly, &mut s);
    }
    // Any trailing colour values on face lines are not read: none of the test files has them.
    s
}

fn load_stl(bytes: &[u8]) -> Soup {
    let mut s = empty();
    let binary = bytes.len() >= 84 && {
        let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
        bytes.len() == 84 + 50 * n
    };
    if binary {
        for rec in bytes[84..].chunks_exact(50) {
            let f = |k: usize| f32::from_le_bytes(rec[4 * k..4 * k + 4].try_into().unwrap()) as f64;
            let base = s.positions.len() as u32;
            for v in 1..4 {
                s.positions
                    .push(DVec3::new(f(3 * v), f(3 * v + 1), f(3 * v + 2)));
            }
            s.triangles.push([base, base + 1, base + 2]);
        }
    } else {
        let text = String::from_utf8_lossy(bytes);
        let mut corners = Vec::new();
        for line in text.lines() {
            let mut it = line.split_whitespace();
            match it.next() {
                Some("vertex") => {
                    let c: Vec<f64> = it.take(3).map(|x| x.parse().unwrap()).collect();
                    corners.push(DVec3::new(c[0], c[1], c[2]));
                }
                Some("endloop") => {
                    let base = s.positions.len() as u32;
                    assert_eq!(corners.len(), 3, "STL facet without 3 vertices");
                    s.positions.append(&mut corners);
                    s.triangles.push([base, base + 1, base + 2]);
                }
                _ => {}
            }
        }
    }
    s
}

fn ply_size(ty: &str) -> usize {
    match ty {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        _ => panic!("PLY type {ty}"),
    }
}

fn ply_read(bytes: &[u8], ty: &str) -> f64 {
    match ty {
        "char" | "int8" => bytes[0] as i8 as f64,
        "uchar" | "uint8" => bytes[0] as f64,
        "short" | "int16" => i16::from_le_bytes([bytes[0], bytes[1]]) as f64,
        "ushort" | "uint16" => u16::from_le_bytes([bytes[0], bytes[1]]) as f64,
        "int" | "int32" => i32::from_le_bytes(bytes[..4].try_into().unwrap()) as f64,
        "uint" | "uint32" => u32::from_le_bytes(bytes[..4].try_into().unwrap()) as f64,
        "float" | "float32" => f32::from_le_bytes(bytes[..4].try_into().unwrap()) as f64,
        "double" | "float64" => f64::from_le_bytes(bytes[..8].try_into().unwrap()),
        _ => panic!("PLY type {ty}"),
    }
}

/// A PLY property: name, value type, and the count type when it is a list.
type PlyProperty = (String, String, Option<String>);

/// PLY, ASCII or binary little-endian; reads `x y z` of `vertex` and the list of `face`.
fn load_ply(bytes: &[u8]) -> Soup {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = String::from_utf8_lossy(&bytes[..end]);
    let ascii = header.contains("format ascii");
    // Elements: name, count, properties (name, type, list count type).
    let mut elements: Vec<(String, usize, Vec<PlyProperty>)> = Vec::new();
    for line in header.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"element") => elements.push((w[1].into(), w[2].parse().unwrap(), Vec::new())),
            Some(&"property") if w[1] == "list" => {
                elements
                    .last_mut()
                    .unwrap()
                    .2
                    .push((w[4].into(), w[3].into(), Some(w[2].into())))
            }
            Some(&"property") => {
                elements
                    .last_mut()
                    .unwrap()
                    .2
                    .push((w[2].into(), w[1].into(), None))
            }
            _ => {}
        }
    }
    let mut s = empty();
    let body = &bytes[end..];
    let text = String::from_utf8_lossy(body);
    let mut words = text.split_ascii_whitespace();
    let mut at = 0usize;
    let mut value = |ty: &str| -> f64 {
        if ascii {
            let w = words.next().unwrap();
            // Single-precision properties hold f32 values, as binary files and trimesh do.
            if ply_size(ty) == 4 && ty.starts_with('f') {
                w.parse::<f32>().unwrap() as f64
            } else {
                w.parse().unwrap()
            }
        } else {
            let v = ply_read(&body[at..], ty);
            at += ply_size(ty);
            v
        }
    };
    for (name, count, props) in &elements {
        for _ in 0..*count {
            let mut xyz = [0.0; 3];
            for (pname, ty, list) in props {
                if let Some(count_ty) = list {
                    let k = value(count_ty) as usize;
                    let poly: Vec<u32> = (0..k).map(|_| value(ty) as u32).collect();
                    if name == "face" {
                        fan(&poly, &mut s);
                    }
                } else {
                    let v = value(ty);
                    match pname.as_str() {
                        "x" => xyz[0] = v,
                        "y" => xyz[1] = v,
                        "z" => xyz[2] = v,
                        _ => {}
                    }
                }
            }
            if name == "vertex" {
                s.positions.push(DVec3::from_array(xyz));
            }
        }
    }
    s
}
