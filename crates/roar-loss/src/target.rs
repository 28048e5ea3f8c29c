//! The reconstruction target T′: a triangle soup cleaned of duplicates, degenerate faces and
//! inward-facing sheets, normalized into the rig's sphere, with one reference render per view
//! (`docs/method.md#target-clean-up-and-renders`).
//!
//! The data walk of [`build_target`]:
//! 1. weld bit-identical positions (−0.0 counts as 0.0);
//! 2. drop degenerate faces (a repeated welded index, or an exactly zero cross product);
//! 3. fit and apply [`Normalization`] (kept in the [`Target`] so results can be mapped back);
//! 4. drop exact duplicate faces (same vertex set, either orientation; the first one stays),
//!    then the vertices no face references;
//! 5. add the reversed twin of every face, render the doubled soup from the star rig with
//!    back-face culling, and sum each face's visible pixels over the views;
//! 6. per twin pair with counts `hi ≥ lo`, drop the lower twin only when `hi/(lo+1) ≥ ratio`
//!    (80); ties and "undecided" pairs keep both twins;
//! 7. render the target normal maps of T′, one per view (culling on, so
//!    the two twins of an undecided pair never z-fight).

use std::collections::HashMap;

use glam::DVec3;
use roar_mesh::spatial::{Normalization, TriangleBvh};
use roar_render::{Camera, Image, RenderOptions, face_pixel_counts, render, star_cameras};

use crate::error::LossError;

/// Views rendered together: bounds the memory of a forward pass (each view of 512² keeps ids,
/// depth and colour, ~6 MB) while keeping both cores busy.
const VIEW_CHUNK: usize = 4;

/// Options of [`build_target`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetOptions {
    /// Cameras per rig axis: the star rig has `views_per_axis²` views (the paper's 6 → 36).
    pub views_per_axis: usize,
    /// Square render resolution in pixels, for the twin counts and the target renders
    /// (supplementary §1.2: 512).
    pub resolution: u32,
    /// A twin is dropped only when its partner has at least `twin_ratio × (its count + 1)`
    /// visible pixels (supplementary §1.2: 80).
    pub twin_ratio: f64,
}

impl Default for TargetOptions {
    fn default() -> Self {
        Self {
            views_per_axis: 6,
            resolution: 512,
            twin_ratio: 80.0,
        }
    }
}

/// What [`build_target`] did to the soup.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TargetStats {
    /// Vertices in the input buffer.
    pub input_vertices: usize,
    /// Faces in the input buffer.
    pub input_faces: usize,
    /// Vertices merged into an earlier bit-identical one.
    pub welded_vertices: usize,
    /// Faces removed because two corners share a welded vertex or their area is exactly zero.
    pub degenerate_faces_removed: usize,
    /// Faces removed because an earlier face has the same vertex set (either orientation).
    pub duplicate_faces_removed: usize,
    /// Twin pairs where one side was dropped (`hi/(lo+1) ≥ ratio`).
    pub twins_dropped: usize,
    /// Twin pairs with different counts below the ratio: both sides kept.
    pub pairs_undecided: usize,
    /// Twin pairs with equal counts (including never seen, 0 and 0): both sides kept.
    pub pairs_tied: usize,
    /// Of the tied pairs, those no camera saw at all.
    pub pairs_unseen: usize,
    /// Vertices removed because no kept face references them (after welding).
    pub unreferenced_vertices_dropped: usize,
    /// Vertices of T′.
    pub output_vertices: usize,
    /// Faces of T′.
    pub output_faces: usize,
}

/// The cleaned target T′ in rig coordinates, with what is needed to compare a source mesh to it.
#[derive(Clone, Debug)]
pub struct Target {
    /// Vertex positions of T′ in rig coordinates (every vertex referenced).
    pub positions: Vec<DVec3>,
    /// Faces of T′: the cleaned soup, both twins of undecided pairs included.
    pub triangles: Vec<[u32; 3]>,
    /// The transform from the input's coordinates into rig coordinates; `invert` maps back.
    pub normalization: Normalization,
    /// The star rig used for the twin counts and the renders.
    pub cameras: Vec<Camera>,
    /// One flat-shaded normal map of T′ per camera, rendered with back-face culling.
    pub renders: Vec<Image>,
    /// Counts of what the clean-up did.
    pub stats: TargetStats,
}

impl Target {
    /// A BVH over T′ (closest point and ray queries).
    pub fn bvh(&self) -> TriangleBvh {
        TriangleBvh::build(&self.positions, &self.triangles)
    }
}

/// Builds the target T′ from a triangle soup (the module docs list the steps).
///
/// Inputs: `positions` (#V, any coordinates), `triangles` (#F indices into `positions`).
/// Errors: an index out of range, a non-finite coordinate on a referenced vertex, no face with
/// positive area, bad options, or a render failure. Deterministic: same input, same output.
pub fn build_target(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    options: &TargetOptions,
) -> Result<Target, LossError> {
    check_options(options)?;
    check_input(positions, triangles)?;
    let mut stats = TargetStats {
        input_vertices: positions.len(),
        input_faces: triangles.len(),
        ..TargetStats::default()
    };

    let (welded_positions, remap) = weld(positions);
    stats.welded_vertices = positions.len() - welded_positions.len();
    let welded: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| t.map(|i| remap[i as usize]))
        .collect();
    let faces: Vec<[u32; 3]> = welded
        .iter()
        .copied()
        .filter(|&t| !is_degenerate(&welded_positions, t))
        .collect();
    stats.degenerate_faces_removed = welded.len() - faces.len();
    if faces.is_empty() {
        return Err(LossError::InvalidTarget(
            "the soup has no face with positive area".into(),
        ));
    }

    let normalization = Normalization::fit(&welded_positions, &faces).ok_or_else(|| {
        LossError::InvalidTarget("the soup's vertices cannot be normalized".into())
    })?;
    let mut normalized = welded_positions;
    normalization.apply_all(&mut normalized);

    let unique = remove_duplicate_faces(&faces);
    stats.duplicate_faces_removed = faces.len() - unique.len();

    let cameras = star_cameras(
        options.views_per_axis,
        options.views_per_axis,
        options.resolution,
        options.resolution,
    );
    // Every pair keeps at least one twin, so no vertex becomes unreferenced after this; the
    // renderer must not see unreferenced (possibly far or non-finite) vertices.
    let (positions_out, unique) = drop_unreferenced(&normalized, &unique);
    stats.unreferenced_vertices_dropped = normalized.len() - positions_out.len();
    let counts = twin_pixel_counts(&positions_out, &unique, &cameras)?;
    let triangles_out = choose_twins(&unique, &counts, options.twin_ratio, &mut stats);
    stats.output_vertices = positions_out.len();
    stats.output_faces = triangles_out.len();

    let renders = render_views(&positions_out, &triangles_out, &cameras, true)?;
    Ok(Target {
        positions: positions_out,
        triangles: triangles_out,
        normalization,
        cameras,
        renders,
        stats,
    })
}

fn check_options(options: &TargetOptions) -> Result<(), LossError> {
    if options.views_per_axis == 0 || options.resolution == 0 {
        return Err(LossError::InvalidTarget(format!(
            "the rig needs at least one view and one pixel (views_per_axis {}, resolution {})",
            options.views_per_axis, options.resolution
        )));
    }
    if !(options.twin_ratio.is_finite() && options.twin_ratio > 0.0) {
        return Err(LossError::InvalidTarget(format!(
            "twin_ratio must be finite and positive, got {}",
            options.twin_ratio
        )));
    }
    Ok(())
}

fn check_input(positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<(), LossError> {
    for (f, t) in triangles.iter().enumerate() {
        for &i in t {
            match positions.get(i as usize) {
                None => {
                    return Err(LossError::InvalidTarget(format!(
                        "face {f} refers to vertex {i}, but there are only {} vertices",
                        positions.len()
                    )));
                }
                Some(p) if !p.is_finite() => {
                    return Err(LossError::InvalidTarget(format!(
                        "vertex {i} (used by face {f}) has a non-finite coordinate"
                    )));
                }
                Some(_) => {}
            }
        }
    }
    Ok(())
}

/// Bit pattern of a coordinate with −0.0 folded into 0.0, so the two weld together.
fn coordinate_key(x: f64) -> u64 {
    if x == 0.0 { 0 } else { x.to_bits() }
}

/// Merges bit-identical positions (−0.0 = 0.0); the first occurrence keeps its place.
/// Returns the unique positions and the old → new index map.
fn weld(positions: &[DVec3]) -> (Vec<DVec3>, Vec<u32>) {
    let mut index: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
    let mut unique = Vec::with_capacity(positions.len());
    let remap = positions
        .iter()
        .map(|p| {
            let key = [p.x, p.y, p.z].map(coordinate_key);
            *index.entry(key).or_insert_with(|| {
                unique.push(*p);
                (unique.len() - 1) as u32
            })
        })
        .collect();
    (unique, remap)
}

/// A face with a repeated index or an exactly zero cross product covers no area.
fn is_degenerate(positions: &[DVec3], t: [u32; 3]) -> bool {
    if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
        return true;
    }
    let [a, b, c] = t.map(|i| positions[i as usize]);
    (b - a).cross(c - a) == DVec3::ZERO
}

/// Keeps the first face of every vertex set (orientation ignored, so a face and its
/// reversed copy count as duplicates).
fn remove_duplicate_faces(faces: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut seen = std::collections::HashSet::with_capacity(faces.len());
    faces
        .iter()
        .copied()
        .filter(|t| {
            let mut key = *t;
            key.sort_unstable();
            seen.insert(key)
        })
        .collect()
}

/// Visible pixels per face of the doubled soup `faces ++ reversed(faces)`, summed over the rig's
/// views with back-face culling. Entry `f` is face `f`, entry
/// `F + f` its twin.
fn twin_pixel_counts(
    positions: &[DVec3],
    faces: &[[u32; 3]],
    cameras: &[Camera],
) -> Result<Vec<u64>, LossError> {
    let doubled: Vec<[u32; 3]> = faces
        .iter()
        .copied()
        .chain(faces.iter().map(|&[a, b, c]| [a, c, b]))
        .collect();
    // Ids are decided before antialiasing, so it is skipped here.
    let options = RenderOptions {
        cull_backfaces: true,
        antialias: false,
    };
    let mut counts = vec![0u64; doubled.len()];
    for chunk in cameras.chunks(VIEW_CHUNK) {
        let renders = render(positions, &doubled, chunk, &options)?;
        for (total, c) in counts.iter_mut().zip(face_pixel_counts(&renders)) {
            *total += u64::from(c);
        }
    }
    Ok(counts)
}

/// Applies the twin rule (a twin goes only when its partner has `twin_ratio` times more
/// pixels) and returns the kept faces, pair by pair (face, then twin).
fn choose_twins(
    faces: &[[u32; 3]],
    counts: &[u64],
    ratio: f64,
    stats: &mut TargetStats,
) -> Vec<[u32; 3]> {
    let n = faces.len();
    let mut kept = Vec::with_capacity(n + n / 8);
    for (f, &[a, b, c]) in faces.iter().enumerate() {
        let (front, back) = (counts[f], counts[n + f]);
        let (keep_front, keep_back) = if front == back {
            stats.pairs_tied += 1;
            if front == 0 {
                stats.pairs_unseen += 1;
            }
            (true, true)
        } else {
            let (hi, lo) = (front.max(back), front.min(back));
            if hi as f64 / (lo as f64 + 1.0) >= ratio {
                stats.twins_dropped += 1;
                (front > back, back > front)
            } else {
                stats.pairs_undecided += 1;
                (true, true)
            }
        };
        if keep_front {
            kept.push([a, b, c]);
        }
        if keep_back {
            kept.push([a, c, b]);
        }
    }
    kept
}

/// Compacts the vertex buffer to the referenced vertices, in their old order.
fn drop_unreferenced(positions: &[DVec3], faces: &[[u32; 3]]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut new_index = vec![u32::MAX; positions.len()];
    for t in faces {
        for &i in t {
            new_index[i as usize] = 0;
        }
    }
    let mut compact = Vec::new();
    for (i, slot) in new_index.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = compact.len() as u32;
            compact.push(positions[i]);
        }
    }
    let faces = faces
        .iter()
        .map(|t| t.map(|i| new_index[i as usize]))
        .collect();
    (compact, faces)
}

/// The antialiased flat-shaded normal maps of a mesh, one per camera, rendered a few views at a
/// time so only the images are kept.
pub fn render_views(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    cameras: &[Camera],
    cull_backfaces: bool,
) -> Result<Vec<Image>, LossError> {
    let options = RenderOptions {
        cull_backfaces,
        antialias: true,
    };
    let mut images = Vec::with_capacity(cameras.len());
    for chunk in cameras.chunks(VIEW_CHUNK) {
        let renders = render(positions, triangles, chunk, &options)?;
        images.extend(renders.views.into_iter().map(|v| v.rgba));
    }
    Ok(images)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weld_merges_signed_zeros_and_keeps_first_order() {
        let p = [
            DVec3::new(0.0, 1.0, 2.0),
            DVec3::new(-0.0, 1.0, 2.0),
            DVec3::new(1.0, 1.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
        ];
        let (unique, remap) = weld(&p);
        assert_eq!(unique.len(), 2);
        assert_eq!(remap, vec![0, 0, 1, 0]);
    }

    #[test]
    fn duplicates_ignore_orientation_and_rotation() {
        let faces = [[0, 1, 2], [1, 2, 0], [2, 1, 0], [0, 1, 3]];
        assert_eq!(remove_duplicate_faces(&faces), vec![[0, 1, 2], [0, 1, 3]]);
    }

    #[test]
    fn twin_rule_drops_only_at_the_ratio() {
        let faces = [[0, 1, 2]; 5];
        // (front, back) pairs: drop back; tie; undecided; drop front exactly at the ratio; unseen.
        let fronts = [800u64, 5, 100, 0, 0];
        let backs = [9u64, 5, 2, 80, 0];
        let counts: Vec<u64> = fronts.iter().chain(&backs).copied().collect();
        let mut stats = TargetStats::default();
        let kept = choose_twins(&faces, &counts, 80.0, &mut stats);
        assert_eq!(stats.twins_dropped, 2);
        assert_eq!(stats.pairs_tied, 2);
        assert_eq!(stats.pairs_unseen, 1);
        assert_eq!(stats.pairs_undecided, 1);
        assert_eq!(kept.len(), 1 + 2 + 2 + 1 + 2);
        assert_eq!(kept[0], [0, 1, 2]);
        assert_eq!(kept[5], [0, 2, 1]);
    }
}
