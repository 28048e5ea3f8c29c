//! The preview picture: input row, output row with its wireframe, loss curve panel; and the
//! `--preview` flag writes it as PNG beside the output.

mod common;

use roar_cli::pipeline::Reconstruction;
use roar_cli::preview::{PreviewOptions, WIRE_RGB, preview_image};

/// Pixels of the picture's region `(x0, y0, w, h)` that are not the white background, and those
/// of the wire colour.
fn count(image: &roar_cli::preview::PreviewImage, region: (u32, u32, u32, u32)) -> (usize, usize) {
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
    let soup = roar_cli::example::chair_soup();
    let out = Reconstruction::new(common::toy_config(200, 6))
        .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
        .unwrap();
    let losses: Vec<f64> = out.stats.optimize.history.iter().map(|r| r.loss).collect();
    let options = PreviewOptions { tile: 96 };
    let image = preview_image(
        (&soup.positions, &soup.triangles),
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
        (&soup.positions, &soup.triangles),
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
    roar_io::write_mesh(&input, &roar_cli::example::chair_soup()).unwrap();
    let args = roar_cli::commands::reconstruct::ReconstructArgs {
        input: Some(input),
        output: Some(dir.path().join("out.obj")),
        faces: Some(200),
        config: None,
        init: None,
        iterations: None,
        resolution: None,
        seed: None,
        best_effort: false,
        no_icp: false,
        report: None,
        preview: Some(dir.path().join("preview.jpg")),
        print_config: false,
        quiet: true,
        force: false,
        keep_topology: false,
        bounds: None,
    };
    let message = roar_cli::commands::reconstruct::run(&args)
        .unwrap_err()
        .to_string();
    assert!(message.contains("name it *.png"), "{message}");
    assert!(!dir.path().join("out.obj").exists());
}
