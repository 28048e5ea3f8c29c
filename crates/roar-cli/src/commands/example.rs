//! `roar example-soup OUTPUT`: writes the README's example soup.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `roar example-soup`.
#[derive(Args, Debug)]
pub struct ExampleArgs {
    /// Where to write the soup (any supported format, by extension).
    pub output: PathBuf,
}

/// Runs `roar example-soup`.
pub fn run(args: &ExampleArgs) -> anyhow::Result<()> {
    crate::checks::check_paths(&[], &[("OUTPUT", &args.output)])?;
    let soup = roar::example::chair_soup();
    roar_io::write_mesh(&args.output, &soup)?;
    eprintln!(
        "wrote {} ({} vertices, {} triangles)",
        args.output.display(),
        soup.positions.len(),
        soup.triangles.len()
    );
    Ok(())
}
