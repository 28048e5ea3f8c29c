//! The preview picture: input row, output row with its wireframe, loss curve panel; and the
//! `--preview` flag writes it as PNG beside the output, for a soup, an SDF and a scan set.

mod common;

use roar::Reconstruction;
use std::path::{Path, PathBuf};

use roar_cli::commands::reconstruct::ReconstructArgs;
use roar_cli::preview::{PreviewImage, PreviewInput, PreviewOptions, WIRE_RGB, preview_image};

/// Pixels of the picture's region `(x0, y0, w, h)` that are not the white background, and those
/// of the wire colour.
fn count(image: &PreviewImage, region: (u32, u32, u32, u32)) -> (usize, usize) {
    let (mut drawn, mut wire) = (0, 0);
    for y in region.1..region.1 + region.3 {
        for x in region.0..region.0 + region.2 {
            let at = ((y * image.width + x) * 4) as usize;
            let rgb = &image.rgba[at..at + 3];
            if rgb != [255, 255, 255] {
                drawn += 1;
            }
            if rgb == WIRE_RGB {
                wire += 1;
            }
        }
    }
    (drawn, wire)
}

#[test]
fn the_preview_shows_input_output_wireframe_and_curve() {
    let soup = roar::example::chair_soup();
    let out = Reconstruction::new(common::toy_config(200, 6))
        .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
        .unwrap();
    let losses: Vec<f64> = out.stats.optimize.history.iter().map(|r| r.loss).collect();
    let options = PreviewOptions { tile: 96 };
    let image = preview_image(
        PreviewInput::Soup(&soup.positions, &soup.triangles),
        (&out.positions, &out.triangles),
        &losses,
        &options,
    )
    .unwrap();
    let t = options.tile;
    assert_eq!((image.width, image.height), (4 * t, 3 * t));
    assert_eq!(image.rgba.len(), (image.width * image.height * 4) as usize);
    for column in 0..4 {
        let (input_drawn, input_wire) = count(&image, (column * t, 0, t, t));
        let (output_drawn, output_wire) = count(&image, (column * t, t, t, t));
        // Each view shows the shape (a sizeable part of the tile), the output with wires.
        assert!(
            input_drawn > (t * t / 20) as usize,
            "input view {column}: {input_drawn}"
        );
        assert!(
            output_drawn > (t * t / 20) as usize,
            "output view {column}: {output_drawn}"
        );
        assert_eq!(input_wire, 0, "input view {column} has wire pixels");
        assert!(output_wire > 0, "output view {column} has no wireframe");
        assert!(
            output_wire < output_drawn,
            "output view {column} is all wire"
        );
    }
    let (_, curve) = count(&image, (0, 2 * t, 4 * t, t));
    assert!(curve > 0, "the loss curve is missing");
    // No history (e.g. `iterations = 0`): the panel keeps only its frame.
    let blank = preview_image(
        PreviewInput::Soup(&soup.positions, &soup.triangles),
        (&out.positions, &out.triangles),
        &[],
        &options,
    )
    .unwrap();
    assert_eq!(count(&blank, (0, 2 * t, 4 * t, t)).1, 0);
}

#[test]
fn the_flag_refuses_a_non_png_name_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("chair.obj");
    roar_io::write_mesh(&input, &roar::example::chair_soup()).unwrap();
    let args = roar_cli::commands::reconstruct::ReconstructArgs {
        input: Some(input),
        output: Some(dir.path().join("out.obj")),
        faces: Some(200),
        preview: Some(dir.path().join("preview.jpg")),
        quiet: true,
        ..Default::default()
    };
    let message = roar_cli::commands::reconstruct::run(&args)
        .unwrap_err()
        .to_string();
    assert!(message.contains("name it *.png"), "{message}");
    assert!(!dir.path().join("out.obj").exists());
}

/// `roar reconstruct INPUT` with a toy config (`faces`, a few iterations) and `--preview`.
fn reconstruct_with_preview(dir: &Path, input: PathBuf, faces: usize) -> anyhow::Result<PathBuf> {
    let mut config = common::toy_config(faces, 6);
    config.target.sdf_trace_grid = 32;
    config.target.scan_icp = false;
    let config_path = dir.join("toy.toml");
    std::fs::write(&config_path, toml::to_string(&config).unwrap()).unwrap();
    let preview = dir.join("preview.png");
    let args = ReconstructArgs {
        input: Some(input),
        output: Some(dir.join("out.obj")),
        faces: Some(faces),
        config: Some(config_path),
        preview: Some(preview.clone()),
        quiet: true,
        ..Default::default()
    };
    roar_cli::commands::reconstruct::run(&args)?;
    Ok(preview)
}

/// Reads a PNG written by `--preview` and checks it is the default picture's size with the
/// input and output drawn in each of the four views and a loss curve.
fn check_preview_png(path: &Path) {
    let decoded = image::open(path).expect("a valid PNG").to_rgba8();
    let image = PreviewImage {
        width: decoded.width(),
        height: decoded.height(),
        rgba: decoded.into_raw(),
    };
    let t = PreviewOptions::default().tile;
    assert_eq!((image.width, image.height), (4 * t, 3 * t));
    for column in 0..4 {
        let (input_drawn, input_wire) = count(&image, (column * t, 0, t, t));
        let (output_drawn, output_wire) = count(&image, (column * t, t, t, t));
        assert!(
            input_drawn > (t * t / 20) as usize,
            "input view {column}: {input_drawn}"
        );
        assert_eq!(input_wire, 0, "input view {column} has wire pixels");
        assert!(
            output_drawn > (t * t / 20) as usize,
            "output view {column}: {output_drawn}"
        );
        assert!(output_wire > 0, "output view {column} has no wireframe");
    }
    assert!(count(&image, (0, 2 * t, 4 * t, t)).1 > 0, "no loss curve");
}

#[test]
fn an_sdf_input_is_pictured_by_its_traced_zero_set() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("ball.sdf.toml");
    std::fs::write(&input, "[shape]\ntype = \"sphere\"\nradius = 0.6\n").unwrap();
    let preview = reconstruct_with_preview(dir.path(), input, 200).unwrap();
    check_preview_png(&preview);
}

/// A range grid (`n × n`, PLY `range_grid`) of the hemisphere `z ≥ 0` of the sphere of radius
/// `r` at the origin, seen by a scanner on the +z axis; cells off the sphere are empty.
fn hemisphere_grid(n: usize, r: f64) -> String {
    let mut points = Vec::new();
    let mut cells = Vec::new();
    for row in 0..n {
        for col in 0..n {
            let x = r * (2.0 * col as f64 / (n - 1) as f64 - 1.0);
            let y = r * (1.0 - 2.0 * row as f64 / (n - 1) as f64);
            let z2 = r * r - x * x - y * y;
            if z2 > 0.0 {
                cells.push(format!("1 {}", points.len()));
                points.push(format!("{x} {y} {}", z2.sqrt()));
            } else {
                cells.push("0".to_string());
            }
        }
    }
    format!(
        "ply\nformat ascii 1.0\nobj_info num_cols {n}\nobj_info num_rows {n}\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element range_grid {}\nproperty list uchar int vertex_indices\nend_header\n{}\n{}\n",
        points.len(),
        cells.len(),
        points.join("\n"),
        cells.join("\n")
    )
}

#[test]
fn a_scan_set_is_pictured_by_its_aligned_patches() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.ply"), hemisphere_grid(24, 0.5)).unwrap();
    std::fs::write(dir.path().join("bottom.ply"), hemisphere_grid(24, 0.5)).unwrap();
    // The second hemisphere turned half a turn about x covers the bottom.
    let conf = dir.path().join("ball.conf");
    std::fs::write(
        &conf,
        "bmesh top.ply 0 0 0 0 0 0 1\nbmesh bottom.ply 0 0 0 1 0 0 0\n",
    )
    .unwrap();
    let preview = reconstruct_with_preview(dir.path(), conf, 200).unwrap();
    check_preview_png(&preview);
}
