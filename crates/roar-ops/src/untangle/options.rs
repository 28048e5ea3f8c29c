//! The options of [`untangle`](super::untangle).

/// Options of [`untangle`](super::untangle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UntangleOptions {
    /// Give up after this many rounds (default 200); unresolved faces are reported.
    pub max_rounds: usize,
    /// Final separation of formerly crossing faces, relative to the bounding-box diagonal
    /// (default 1e-6).
    pub margin_rel: f64,
    /// A bad vertex moves by this fraction of its mean incident edge length per round
    /// (default 0.25).
    pub step_fraction: f64,
    /// At most this many vertices move per round through region growing (default 100 000).
    pub max_region: usize,
    /// A crossing face whose aspect ratio (`roar_mesh::spatial::triangle_quality`) is at or
    /// above this is offered an edge collapse at once (default 10, the finish's sliver limit;
    /// `f64::INFINITY` disables).
    pub sliver_quality: f64,
    /// A face still crossing after this many consecutive rounds is offered an edge collapse
    /// (default 8).
    pub stuck_rounds: usize,
    /// Allow edge collapses at all (default true). Without them the topology is untouched.
    pub allow_collapses: bool,
    /// At most this many collapses per round (default 64); each rebuilds the BVH.
    pub max_collapses_per_round: usize,
}

impl Default for UntangleOptions {
    fn default() -> Self {
        Self {
            max_rounds: 200,
            margin_rel: 1e-6,
            step_fraction: 0.25,
            max_region: 100_000,
            sliver_quality: 10.0,
            stuck_rounds: 8,
            allow_collapses: true,
            max_collapses_per_round: 64,
        }
    }
}
