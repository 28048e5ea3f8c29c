//! # roar-eval
//!
//! Will own the metrics on arbitrary triangle soups: Chamfer distance, normal consistency,
//! triangle quality, self-intersections, manifoldness and topology, gathered in a serde `Report`.
