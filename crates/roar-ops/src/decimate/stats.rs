//! What a decimation reports: [`DecimateStats`] and the [`VetoCounts`] in it.

use roar_mesh::Remap;
use std::fmt;

/// How many popped collapses each check rejected.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct VetoCounts {
    /// [`Mesh::can_collapse`](roar_mesh::Mesh::can_collapse) refused (link condition, valence 3, tetrahedron).
    pub topology: usize,
    /// A face normal would turn past `min_normal_dot`.
    pub normal_flip: usize,
    /// A new face would be near-degenerate (|cross| ≤ 1e-10 · longest edge²).
    pub degenerate: usize,
    /// A new face would exceed the current quality bound.
    pub quality: usize,
    /// A new face would intersect another face.
    pub self_intersection: usize,
}

impl VetoCounts {
    /// Total number of vetoes.
    pub fn total(&self) -> usize {
        self.topology + self.normal_flip + self.degenerate + self.quality + self.self_intersection
    }

    pub(crate) fn add(&mut self, o: &VetoCounts) {
        self.topology += o.topology;
        self.normal_flip += o.normal_flip;
        self.degenerate += o.degenerate;
        self.quality += o.quality;
        self.self_intersection += o.self_intersection;
    }
}

impl fmt::Display for VetoCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "topology {}, normal flip {}, degenerate {}, quality {}, self-intersection {}",
            self.topology, self.normal_flip, self.degenerate, self.quality, self.self_intersection
        )
    }
}

/// Outcome of [`decimate`](super::decimate).
#[derive(Debug, Clone, PartialEq)]
pub struct DecimateStats {
    /// Face count before.
    pub initial_faces: usize,
    /// Face count after.
    pub final_faces: usize,
    /// The requested face count.
    pub target: usize,
    /// Whether `final_faces == target` (always true unless `best_effort` kept a closer mesh, or
    /// the target was at or above the initial count, see `noop`).
    pub reached_target: bool,
    /// The target was ≥ the initial face count: nothing was done (decimation never adds faces).
    pub noop: bool,
    /// Collapses applied.
    pub collapses: usize,
    /// Vetoes by reason over the whole run.
    pub vetoes: VetoCounts,
    /// The quality bound in force when the run ended (`None` for a no-op).
    pub quality_bound: Option<f64>,
    /// Heap passes run (each re-queues every live edge).
    pub passes: usize,
    /// Largest cost of an applied collapse: its quadric error (squared distance × area units,
    /// at least the tiny cost floor), times its quality penalty when it had one.
    pub max_cost: f64,
    /// The compaction done at the end (old → new ids); `None` for a no-op. Per-vertex caller
    /// data kept in step by the collapse callback must be permuted with it.
    pub remap: Option<Remap>,
}
