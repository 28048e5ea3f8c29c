//! Prints `roar_eval::Report` as JSON, like `roar eval MESH [--ref REF] --json`, for the
//! cross-check script when the CLI has no `eval` command:
//! `eval_json MESH [--ref REF] [--samples N] [--seed S] [--no-self-intersections]`.

use std::path::PathBuf;

use roar_eval::{EvalOptions, evaluate};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut mesh = None;
    let mut reference = None;
    let mut options = EvalOptions::default();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--ref" => reference = Some(PathBuf::from(args.next().ok_or("--ref needs a path")?)),
            "--samples" => options.chamfer.samples = args.next().ok_or("--samples N")?.parse()?,
            "--seed" => options.chamfer.seed = args.next().ok_or("--seed S")?.parse()?,
            "--no-self-intersections" => options.self_intersections = None,
            "--json" => {}
            _ => mesh = Some(PathBuf::from(a)),
        }
    }
    let mesh = roar_io::read_mesh(&mesh.ok_or("usage: eval_json MESH [--ref REF]")?)?;
    let reference = reference.map(|r| roar_io::read_mesh(&r)).transpose()?;
    let report = evaluate(
        &mesh.positions,
        &mesh.triangles,
        reference
            .as_ref()
            .map(|r| (r.positions.as_slice(), r.triangles.as_slice())),
        &options,
    )?;
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}
