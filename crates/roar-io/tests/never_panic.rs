//! Property tests: every reader returns (Ok or Err, never panics) on random bytes and on valid
//! files with bytes flipped, removed, inserted or cut off; whatever it accepts is a valid soup.

mod common;

use proptest::prelude::*;
use roar_io::{MeshFormat, read_mesh_bytes};

const FORMATS: [MeshFormat; 5] = [
    MeshFormat::Obj,
    MeshFormat::Ply,
    MeshFormat::Stl,
    MeshFormat::Off,
    MeshFormat::Gltf,
];

/// Feeds `bytes` to every reader; an accepted soup must pass `validate`.
fn read_everywhere(bytes: &[u8]) {
    for format in FORMATS {
        match read_mesh_bytes(bytes, "fuzz", format) {
            Ok(soup) => assert_eq!(
                soup.validate(),
                Ok(()),
                "{format:?} accepted an invalid soup"
            ),
            Err(e) => {
                let message = e.to_string();
                assert!(message.starts_with("fuzz"), "{message}");
                assert!(!message.contains('\n'), "{message}");
            }
        }
    }
}

/// One edit of a byte buffer.
#[derive(Debug, Clone)]
enum Edit {
    Flip { at: usize, bit: u8 },
    Set { at: usize, value: u8 },
    Remove { at: usize, len: usize },
    Insert { at: usize, bytes: Vec<u8> },
    Truncate { at: usize },
}

fn edit() -> impl Strategy<Value = Edit> {
    // Positions are taken modulo the buffer length when applied.
    prop_oneof![
        (any::<usize>(), 0u8..8).prop_map(|(at, bit)| Edit::Flip { at, bit }),
        (
            any::<usize>(),
            prop::sample::select(b" \n\r-.0123456789eEnaif/#".to_vec())
        )
            .prop_map(|(at, value)| Edit::Set { at, value }),
        (any::<usize>(), 1usize..40).prop_map(|(at, len)| Edit::Remove { at, len }),
        (any::<usize>(), prop::collection::vec(any::<u8>(), 1..12))
            .prop_map(|(at, bytes)| Edit::Insert { at, bytes }),
        any::<usize>().prop_map(|at| Edit::Truncate { at }),
    ]
}

fn apply(bytes: &mut Vec<u8>, edit: &Edit) {
    let n = bytes.len().max(1);
    match edit {
        Edit::Flip { at, bit } => {
            if !bytes.is_empty() {
                bytes[at % n] ^= 1 << bit;
            }
        }
        Edit::Set { at, value } => {
            if !bytes.is_empty() {
                bytes[at % n] = *value;
            }
        }
        Edit::Remove { at, len } => {
            let start = at % n;
            let end = (start + len).min(bytes.len());
            if start < end {
                bytes.drain(start..end);
            }
        }
        Edit::Insert { at, bytes: new } => {
            let at = at % (bytes.len() + 1);
            bytes.splice(at..at, new.iter().copied());
        }
        Edit::Truncate { at } => bytes.truncate(at % n),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..2000)) {
        read_everywhere(&bytes);
    }

    #[test]
    fn random_text_never_panics(text in "[ \\nvfOFplyasciement0-9.\\-/#]{0,400}") {
        read_everywhere(text.as_bytes());
    }

    #[test]
    fn mutated_valid_files_never_panic(
        which in 0usize..7,
        edits in prop::collection::vec(edit(), 1..6),
    ) {
        let (_, mut bytes) = common::valid_files().swap_remove(which);
        for e in &edits {
            apply(&mut bytes, e);
        }
        read_everywhere(&bytes);
    }

    #[test]
    fn mutated_ply_headers_never_panic(
        big in any::<bool>(),
        edits in prop::collection::vec(edit(), 1..4),
    ) {
        // Edits confined to the header (counts, types, names) stress the element walker.
        let (_, bytes) = common::valid_files().swap_remove(if big { 4 } else { 3 });
        let header_len = bytes.windows(10).position(|w| w == b"end_header").unwrap();
        let mut header = bytes[..header_len].to_vec();
        for e in &edits {
            apply(&mut header, e);
        }
        header.extend_from_slice(&bytes[header_len..]);
        read_everywhere(&header);
    }

    #[test]
    fn mutated_gltf_files_never_panic(
        binary in any::<bool>(),
        edits in prop::collection::vec(edit(), 1..6),
    ) {
        let mut bytes = if binary { valid_gltf().glb() } else { valid_gltf().gltf_embedded() };
        for e in &edits {
            apply(&mut bytes, e);
        }
        read_everywhere(&bytes);
    }
}

/// A tetrahedron under a mirrored node inside a translated parent: exercises the transforms,
/// the index accessor and the buffer view bounds.
fn valid_gltf() -> common::gltf::GltfBuilder {
    let (points, indices) = common::gltf::tetrahedron();
    let mut b = common::gltf::GltfBuilder::default();
    let pos = b.add_positions(&points);
    let idx = b.add_indices_u16(&indices.iter().map(|&i| i as u16).collect::<Vec<_>>());
    let mesh = b.add_mesh(pos, Some(idx), None);
    let child = b.add_node(&format!(r#""mesh":{mesh},"scale":[-1,2,1]"#));
    let root = b.add_node(&format!(r#""children":[{child}],"translation":[1,2,3]"#));
    b.add_scene(&[root]);
    b
}
