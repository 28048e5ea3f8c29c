//! # roar-io
//!
//! `TriangleSoup` (plain buffers in which anything goes) and readers and writers for the mesh
//! formats roar speaks: OBJ, PLY, STL and OFF; image dumps; atomic writes.
