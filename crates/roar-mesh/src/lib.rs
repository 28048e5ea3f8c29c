//! # roar-mesh
//!
//! The half-edge mesh of roar: **closed, oriented, 2-manifold triangle meshes** with typed `u32`
//! handles, implicit twins (`twin(h) = h ^ 1`, `edge(h) = h >> 1`) and struct-of-arrays storage,
//! plus the local operators (edge flip, half-edge collapse, edge split, face split 1→3) that the
//! remeshing blocks are built from. Soups that violate the invariant never enter this type: they
//! live as plain buffers in `roar-io` and `roar-eval`.
//!
//! The module [`spatial`] holds the geometric kernels on plain buffers (`&[DVec3]`,
//! `&[[u32; 3]]`) that every crate shares.

pub mod spatial;
