//! Helper shared by the `spatial_*` integration tests and the `spatial_timings` example:
//! locating the real test meshes (read them with `roar_io::read_mesh`).

#![allow(dead_code)]

use std::path::PathBuf;

/// The folder named by `ROAR_TEST_DATA`, or `None` (with a note) when it is unset and we are not
/// on CI. Panics if it is unset on CI or names a missing folder.
pub fn test_data_dir() -> Option<PathBuf> {
    match std::env::var_os("ROAR_TEST_DATA") {
        Some(dir) => {
            let dir = PathBuf::from(dir);
            assert!(
                dir.is_dir(),
                "ROAR_TEST_DATA={} is not a folder",
                dir.display()
            );
            Some(dir)
        }
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "ROAR_TEST_DATA must be set on CI"
            );
            eprintln!("note: ROAR_TEST_DATA is unset, skipping a test on real meshes");
            None
        }
    }
}
