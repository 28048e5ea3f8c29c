//! One evaluation of the loop's objective or a part of it (value and gradient) on the loss
//! bench's fixture, for instruction counts that repeat on a loaded machine:
//!
//! ```sh
//! ROAR_TEST_DATA=… RAYON_NUM_THREADS=1 valgrind --tool=callgrind \
//!     --toggle-collect='*value_and_grad*' target/release/examples/loss_once [FACES] [PART]
//! ```
//!
//! FACES defaults to 10,000; PART is `loop` (default: the loop's and the polish's objective,
//! coarse rig), `full` (the paper's, full rig), `render` or `render_coarse` (forward +
//! backward) or `planar`. Fixture and source: `benches/common/homer.rs`.

#[path = "../benches/common/homer.rs"]
mod homer;

use homer::Homer;
use roar::{default_loss, planar_options};
use roar_loss::{Loss, PlanarLoss, RenderLoss};

fn main() {
    let mut args = std::env::args().skip(1);
    let faces: usize = args.next().map_or(10_000, |a| a.parse().expect("FACES"));
    let part = args.next().unwrap_or_else(|| "loop".into());
    let homer = Homer::load().expect("set ROAR_TEST_DATA");
    let (positions, triangles) = homer.source(faces);
    let mut loss: Box<dyn Loss> = match part.as_str() {
        "loop" => default_loss(&homer.prepared(true)).unwrap(),
        "full" => default_loss(&homer.prepared(false)).unwrap(),
        "render" => Box::new(RenderLoss::new(&homer.target)),
        "render_coarse" => Box::new(RenderLoss::from_renders(
            &homer.coarse_cameras,
            &homer.coarse_renders,
        )),
        "planar" => Box::new(
            PlanarLoss::new(
                &homer.cloud.points,
                &homer.cloud.normals,
                &planar_options(&homer.config),
            )
            .unwrap(),
        ),
        other => panic!("PART is loop, full, render, render_coarse or planar, not {other}"),
    };
    let value = loss.value_and_grad(&positions, &triangles).unwrap().0;
    println!("{part} loss at {} faces: {value}", triangles.len());
}
