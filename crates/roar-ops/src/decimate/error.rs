//! Why a decimation failed: [`DecimateError`].

use super::stats::VetoCounts;

/// Errors of [`decimate`](super::decimate). On error the mesh is unchanged, except for `BudgetNotReached`, which
/// leaves the closest mesh reached (compacted).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecimateError {
    /// A closed triangle mesh always has an even face count (3F = 2E).
    #[error(
        "face budget {target} is odd: a closed triangle mesh has an even face count; use {below} or {above}"
    )]
    OddTarget {
        /// The requested count.
        target: usize,
        /// Nearest even count below.
        below: usize,
        /// Nearest even count above.
        above: usize,
    },
    /// The target is below what the components and their genera allow.
    #[error(
        "face budget {target} is impossible: {components} component(s) of total genus {genus} need at least {minimum} faces"
    )]
    TargetBelowMinimum {
        /// The requested count.
        target: usize,
        /// Smallest face count a closed mesh with these components and genera can have.
        minimum: usize,
        /// Connected components.
        components: usize,
        /// Total genus.
        genus: usize,
    },
    /// The vetoes blocked every remaining collapse above the target.
    #[error(
        "could not decimate to {target} faces: stopped at {reached} ({} too many); last pass blocked by {reasons}",
        reached - target
    )]
    BudgetNotReached {
        /// The requested count.
        target: usize,
        /// The face count reached (the mesh is left there).
        reached: usize,
        /// Vetoes of the last pass: why the remaining collapses were refused.
        reasons: VetoCounts,
    },
    /// An option is out of range.
    #[error("invalid decimation option {name}: {reason}")]
    InvalidOption {
        /// Field name.
        name: &'static str,
        /// What is expected.
        reason: &'static str,
    },
}
