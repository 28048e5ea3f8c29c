//! Which blocks of the loop create self-intersections: runs the pipeline on a mesh file with
//! every default block wrapped in a counter of intersecting faces before and after it, and
//! prints, per block, how often it raised the count and by how much in total.
//! `cargo run --release -p roar --example block_intersections -- FILE [FACES] [RESOLUTION]`.
//! Diagnostic only: the exact all-pairs check after every block makes the run much slower.

use roar::{InitConfig, ReconstructConfig, Reconstruction, ScheduledBlock};
use roar_mesh::TrackedMesh;
use roar_mesh::spatial::count_intersecting_faces;
use roar_ops::blocks::block::{Block, BlockContext, BlockStats};
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::Path;
use std::rc::Rc;

/// Per block name: (times it raised the count, faces added); plus the last count seen, to
/// attribute rises between blocks to the optimizer step.
#[derive(Default)]
struct Counts {
    by_block: BTreeMap<&'static str, (usize, usize)>,
    last: usize,
}

type Tally = Rc<RefCell<Counts>>;

fn raise(counts: &mut Counts, name: &'static str, from: usize, to: usize) {
    if to > from {
        let entry = counts.by_block.entry(name).or_default();
        entry.0 += 1;
        entry.1 += to - from;
    }
}

struct Counted {
    inner: Box<dyn Block>,
    tally: Tally,
}

impl Block for Counted {
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn apply(&mut self, mesh: &mut TrackedMesh, ctx: &BlockContext) -> BlockStats {
        let before = count_intersecting_faces(mesh);
        let stats = self.inner.apply(mesh, ctx);
        let after = count_intersecting_faces(mesh);
        let mut counts = self.tally.borrow_mut();
        let last = counts.last;
        raise(&mut counts, "optimizer step (with limiter)", last, before);
        raise(&mut counts, self.inner.name(), before, after);
        counts.last = after;
        stats
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let soup = roar_io::read_mesh(Path::new(&args[0])).expect("readable mesh");
    let config = ReconstructConfig {
        faces: args.get(1).map_or(1000, |s| s.parse().unwrap()),
        init: InitConfig {
            init_resolution: args.get(2).map_or(128, |s| s.parse().unwrap()),
            ..Default::default()
        },
        ..ReconstructConfig::default()
    };
    let tally: Tally = Rc::default();
    let mut reconstruction = Reconstruction::new(config);
    let blocks = std::mem::take(&mut reconstruction.blocks);
    reconstruction.blocks = blocks
        .into_iter()
        .map(|s| ScheduledBlock {
            block: Box::new(Counted {
                inner: s.block,
                tally: tally.clone(),
            }),
            ..s
        })
        .collect();
    let out = reconstruction
        .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
        .expect("reconstruction");
    println!(
        "untangle failures {:?}, finished from iteration {}",
        out.stats.optimize.untangle_failures, out.stats.optimize.finished_from_iteration
    );
    for (name, (times, faces)) in tally.borrow().by_block.iter() {
        println!("{name}: raised the count {times} times, by {faces} faces in total");
    }
}
