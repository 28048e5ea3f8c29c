//! Which face counts a mesh can be decimated to ([`minimum_faces`]), and the up-front checks of a
//! request.

use super::error::DecimateError;
use super::options::{DecimateOptions, check_options};
use super::stats::{DecimateStats, VetoCounts};
use roar_mesh::Mesh;

/// Smallest face count of a closed orientable triangulated surface of genus `g`: `2(V − 2 + 2g)`
/// with the minimal vertex count `V` (Heawood's bound `⌈(7 + √(1 + 48g))/2⌉`, 10 for genus 2,
/// 4 for the sphere).
pub fn minimum_faces_for_genus(g: usize) -> usize {
    let v = match g {
        0 => 4,
        2 => 10,
        _ => ((7.0 + (1.0 + 48.0 * g as f64).sqrt()) / 2.0 - 1e-9).ceil() as usize,
    };
    2 * (v - 2 + 2 * g)
}

/// Smallest face count `mesh` can be decimated to without changing its components or genera
/// (the sum of [`minimum_faces_for_genus`] over components). Greedy collapse may stop above it.
pub fn minimum_faces(mesh: &Mesh) -> usize {
    mesh.component_genera()
        .into_iter()
        .map(minimum_faces_for_genus)
        .sum()
}

/// The up-front checks of [`decimate_with`](super::decimate_with): `Err` for a bad option, an odd target or one below
/// the minimum; `Ok(Some(stats))` when the target is at or above the face count (nothing to do).
pub(super) fn check_request(
    mesh: &Mesh,
    target_faces: usize,
    options: &DecimateOptions,
) -> Result<Option<DecimateStats>, DecimateError> {
    check_options(options)?;
    if target_faces % 2 == 1 {
        return Err(DecimateError::OddTarget {
            target: target_faces,
            below: target_faces - 1,
            above: target_faces + 1,
        });
    }
    let initial = mesh.n_faces();
    if target_faces >= initial {
        return Ok(Some(DecimateStats {
            initial_faces: initial,
            final_faces: initial,
            target: target_faces,
            reached_target: target_faces == initial,
            noop: true,
            collapses: 0,
            vetoes: VetoCounts::default(),
            quality_bound: None,
            passes: 0,
            max_cost: 0.0,
            remap: None,
        }));
    }
    let minimum = minimum_faces(mesh);
    if target_faces < minimum {
        return Err(DecimateError::TargetBelowMinimum {
            target: target_faces,
            minimum,
            components: mesh.components().0,
            genus: mesh.genus(),
        });
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_faces_follow_heawood() {
        assert_eq!(minimum_faces_for_genus(0), 4);
        assert_eq!(minimum_faces_for_genus(1), 14); // Császár torus, 7 vertices
        assert_eq!(minimum_faces_for_genus(2), 24); // 10 vertices
        assert_eq!(minimum_faces_for_genus(3), 28); // 10 vertices (Heawood)
    }
}
