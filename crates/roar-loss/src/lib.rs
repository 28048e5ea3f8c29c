//! # roar-loss
//!
//! The reconstruction target (the cleaned soup T′, its renders, the oriented point cloud P) and the
//! losses that drive the vertices: the render loss, the planar projection loss and the SDF loss
//! (`docs/method.md#render-loss` and the sections after it), behind the common [`Loss`] trait so a
//! researcher can add or swap a term without touching the pipeline.

mod error;
pub mod knn_projector;
mod loss;
pub mod planar;
mod point_tree;

pub use error::LossError;
pub use knn_projector::{KnnOptions, KnnPlanarProjector, PlanarMode};
pub use loss::Loss;
pub use planar::{PlanarLoss, PlanarOptions, PlanarStats};

pub mod point_cloud;
pub mod render_loss;
pub mod sdf_loss;
pub mod sharp_edges;
pub mod target;
mod weighted_sum;

pub use point_cloud::{
    PointCloud, PointCloudOptions, point_cloud, point_cloud_of_soup, two_sided_faces,
};
pub use render_loss::{CoarseViews, RenderLoss};
pub use roar_mesh::spatial::{Sdf, SdfEvaluations};
pub use sdf_loss::{SdfLoss, SdfLossOptions};
pub use sharp_edges::{SharpEdge, SharpEdgeOptions, sharp_edge_samples, sharp_edges};
pub use target::{Target, TargetOptions, TargetStats, build_target, render_views};
pub use weighted_sum::WeightedSum;
