//! Shared by the profiling examples: a checksum to tell whether a speed-up changed any output.
#![allow(dead_code)]

use roar_mesh::Mesh;

/// 64-bit FNV-1a over whole words.
pub struct Fnv(u64);

impl Fnv {
    /// The FNV offset basis.
    pub fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    /// Mixes in one word.
    pub fn eat(&mut self, x: u64) {
        self.0 = (self.0 ^ x).wrapping_mul(0x0100_0000_01b3);
    }

    /// The hash so far.
    pub fn finish(&self) -> u64 {
        self.0
    }
}

/// FNV-1a over the bits of the positions and the triangle indices of the compacted mesh.
pub fn mesh_checksum(mesh: &Mesh) -> u64 {
    let (positions, triangles) = mesh.to_triangles();
    let mut h = Fnv::new();
    for p in positions {
        for x in p.to_array() {
            h.eat(x.to_bits());
        }
    }
    for t in triangles {
        for i in t {
            h.eat(u64::from(i));
        }
    }
    h.finish()
}
