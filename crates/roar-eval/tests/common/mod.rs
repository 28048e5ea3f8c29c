//! Where the shared test meshes live, and procedural shapes.
#![allow(dead_code)]

use std::path::PathBuf;

pub mod shapes;

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
