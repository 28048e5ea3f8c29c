//! The Move Vertices optimizer (paper §3.1; the exact step is the authors' code's,
//! `docs/method.md#optimizer`): a VectorAdam-like step whose size follows the
//! local edge length, with a Laplacian term added in gradient space.
//!
//! The optimizer works on plain buffers: positions `&mut [DVec3]`, per-vertex gradients
//! `&[DVec3]` and the triangles `&[[u32; 3]]` of the current mesh. Vertex ids are indices into
//! these arrays. It keeps one [`VertexState`] row per vertex id; the topology operators of the
//! remeshing blocks change the vertex set, and the rows follow: the optimizer is a
//! [`roar_mesh::VertexStore`], so every operator and compaction made through a
//! [`roar_mesh::TrackedMesh`] over it calls the matching transfer method
//! ([`Optimizer::on_collapse`], [`Optimizer::on_edge_split`], [`Optimizer::on_face_split`],
//! [`Optimizer::grow`], [`Optimizer::apply_remap`]).
//!
//! One step, for every live vertex v (a vertex referenced by at least one triangle), with the
//! global step counter t = 1, 2, … that remeshing never resets:
//!
//! ```text
//! g   = ∂L/∂v (non-finite → 0) + w_lap · ν_v · δ_v        δ_v = v − mean of the 1-ring
//! if t > 1: g clamped per component to ±grad_lim·|m1|    (only where m1 ≠ 0, note 6)
//! m1  = ulerp(m1, g, β1, t);   m2 = ulerp(m2, ‖g‖², β2, t)
//! u   = m1 / (√m2 + 1e-8);     ν  = ulerp(ν, ‖u‖, β3, t)
//! ℓ_v = min(shortest incident edge, edge_len_max)
//! v  ← v − η·min(1, t(1−β1)/ramp) · ℓ_v · u
//! ```
//!
//! δ_v and ℓ_v are computed from the positions *before* the step, for all vertices at once, so
//! the result does not depend on the vertex order or on the thread count.
//!
//! ```
//! use glam::DVec3;
//! use roar_ops::optim::{Optimizer, OptimizerOptions};
//!
//! // A tetrahedron pulled toward the origin by L = Σ‖v‖².
//! let mut positions = vec![DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
//! let triangles = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
//! let mut opt = Optimizer::new(positions.len(), OptimizerOptions::default())?;
//! for _ in 0..10 {
//!     let gradient: Vec<DVec3> = positions.iter().map(|p| 2.0 * *p).collect();
//!     let stats = opt.step(&mut positions, &triangles, &gradient)?;
//!     assert!(stats.max_move <= 0.05 * 0.15);
//! }
//! assert_eq!(opt.step_count(), 10);
//! # Ok::<(), roar_ops::optim::OptimError>(())
//! ```

mod adjacency;
mod error;
mod optimizer;
mod options;
mod state;
mod transfer;

pub use error::OptimError;
pub use optimizer::{Optimizer, StepStats, VELOCITY_EPSILON, ulerp, ulerp_weights};
pub use options::OptimizerOptions;
pub use state::VertexState;
