//! The pipeline's stages in the order [`crate::Reconstruction::run`] calls them; each takes
//! the shared [`crate::run::Run`] state and records its figures there.

pub(crate) mod finish;
pub(crate) mod init;
pub(crate) mod optimize;
pub(crate) mod prepare;
