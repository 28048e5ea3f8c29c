#!/usr/bin/env python3
"""Tests of scripts/module-cycles.py: `python3 scripts/test_module_cycles.py`.

Each test writes a small fixture crate into a temporary directory and checks the edges, upward
imports and cycles the script finds in it, and its exit code."""
import importlib.util
import io
import os
import subprocess
import sys
import tarfile
import tempfile
import textwrap
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
SCRIPT = os.path.join(HERE, 'module-cycles.py')

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts
_spec = importlib.util.spec_from_file_location('module_cycles', SCRIPT)
mc = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mc)


def write_tree(root, files):
    for rel, text in files.items():
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, 'w') as f:
            f.write(textwrap.dedent(text) if isinstance(text, str) else lines_at(text))


def lines_at(numbered):
    """A file with each text of {line number: text} on its line (multi-line texts run on)."""
    out = []
    for n in sorted(numbered):
        assert len(out) < n, 'line %d overlaps the text before it' % n
        out.extend([''] * (n - 1 - len(out)))
        out.extend(numbered[n].split('\n'))
    return '\n'.join(out) + '\n'


def run_script(*roots):
    p = subprocess.run([sys.executable, SCRIPT, *roots], capture_output=True, text=True)
    return p.returncode, p.stdout


class Fixture(unittest.TestCase):
    def crate(self, files):
        """The src folder of a crate of `files`; the analysis: edges, upward imports, cycles."""
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        root = os.path.join(tmp.name, 'src')
        write_tree(root, files)
        edges, upward = mc.Crate(root).analyse()
        self.root = root
        self.edges = {a: set(bs) for a, bs in edges.items()}
        self.upward = {(os.path.relpath(p, root), line, cur, target, item)
                       for p, line, cur, target, item, _ in upward}
        self.cycles = mc.sccs(edges)
        return root

    def upward_items(self):
        return {(cur, target, item) for _, _, cur, target, item in self.upward}


class Patterns(Fixture):
    def test_grouped_super_import_of_parent_items_is_upward(self):
        self.crate({
            'lib.rs': 'pub mod a;\n',
            'a/mod.rs': '''\
                mod child;
                pub struct Thing;
                pub fn helper() {}
                ''',
            'a/child.rs': '''\
                use std::fmt;
                use super::{Thing, helper};
                pub fn go() {}
                ''',
        })
        self.assertEqual(self.upward, {('a/child.rs', 2, 'a::child', 'a', 'Thing'),
                                       ('a/child.rs', 2, 'a::child', 'a', 'helper')})
        self.assertEqual(self.edges['a::child'], {'a'})
        # The parent only declares the child: no downward edge, so no cycle, but still flagged.
        self.assertEqual(self.edges['a'], set())
        self.assertEqual(self.cycles, [])
        self.assertEqual(run_script(self.root)[0], 1)

    def test_parent_calling_child_with_upward_import_is_a_cycle(self):
        self.crate({
            'lib.rs': 'pub mod a;\n',
            'a/mod.rs': '''\
                mod child;
                pub struct Thing;
                pub fn run() {
                    child::go();
                }
                ''',
            'a/child.rs': '''\
                use super::Thing;
                pub fn go() {}
                ''',
        })
        self.assertEqual(self.edges['a'], {'a::child'})
        self.assertEqual(self.cycles, [['a', 'a::child']])
        code, out = run_script(self.root)
        self.assertEqual(code, 1)
        self.assertIn("module cycles: [['a', 'a::child']]", out)
        self.assertIn('a/child.rs:1: a::child -> a: Thing', out)
        self.assertIn('a -> a::child  (', out)

    def test_parent_calling_child_alone_is_clean(self):
        self.crate({
            'lib.rs': 'pub mod a;\n',
            'a/mod.rs': '''\
                mod child;
                pub use child::Thing;
                pub fn run() {
                    child::go();
                }
                ''',
            'a/child.rs': '''\
                pub struct Thing;
                pub fn go() {}
                ''',
        })
        self.assertEqual(self.edges['a'], {'a::child'})
        self.assertEqual(self.upward, set())
        self.assertEqual(self.cycles, [])
        code, out = run_script(self.root)
        self.assertEqual(code, 0, out)
        self.assertIn('module cycles: []\nupward imports: []\n', out)

    def test_sibling_through_super_is_a_sibling_edge(self):
        self.crate({
            'lib.rs': 'pub mod a;\n',
            'a/mod.rs': 'mod one;\nmod two;\n',
            'a/one.rs': '''\
                use super::two::Two;
                pub struct One;
                ''',
            'a/two.rs': '''\
                pub struct Two;
                pub fn f() -> super::one::One { todo!() }
                ''',
        })
        self.assertEqual(self.upward, set())
        self.assertEqual(self.edges['a::one'], {'a::two'})
        self.assertEqual(self.edges['a::two'], {'a::one'})
        self.assertEqual(self.cycles, [['a::one', 'a::two']])
        self.assertEqual(run_script(self.root)[0], 1)

    def test_nested_crate_groups_and_super_super(self):
        self.crate({
            'lib.rs': 'pub mod w;\npub mod x;\npub mod y;\n',
            'w.rs': 'pub struct W;\n',
            'x.rs': '''\
                use crate::{
                    y::{Y1, inner::{Z, self as zz}},
                    w,
                };
                ''',
            'y/mod.rs': 'pub mod inner;\npub struct Y1;\n',
            'y/inner/mod.rs': 'pub mod deep;\npub struct Z;\n',
            'y/inner/deep.rs': 'use super::super::Y1;\nuse crate::w::W;\n',
        })
        self.assertEqual(self.edges['x'], {'y', 'y::inner', 'w'})
        self.assertEqual(self.edges['y::inner::deep'], {'y', 'w'})
        self.assertEqual(self.upward, {('y/inner/deep.rs', 1, 'y::inner::deep', 'y', 'Y1')})

    def test_comments_and_literals_do_not_count(self):
        self.crate({
            'lib.rs': 'pub mod a;\n',
            'a/mod.rs': '''\
                //! Module docs naming [`super::Thing`] and `crate::a::Thing`.
                mod child;
                pub struct Thing;
                pub fn run() { child::go(); }
                ''',
            'a/child.rs': '''\
                //! Inner docs: use super::Thing;
                /// Outer docs: [`super::Thing`].
                // use super::Thing;
                /* block use super::Thing; /* nested super::Thing */ still comment super::Thing */
                pub fn go<'a>(s: &'a str) -> char {
                    let _ = "use super::Thing; \\" super::Thing";
                    let _ = r#"super::Thing "quoted" crate::a::Thing"#;
                    let _ = b"super::Thing";
                    let _ = '"';
                    let _ = '{';
                    let _ = '\\'';
                    'x'
                }
                ''',
        })
        self.assertEqual(self.upward, set())
        self.assertEqual(self.edges['a::child'], set())
        self.assertEqual(self.cycles, [])
        self.assertEqual(run_script(self.root)[0], 0)

    def test_cfg_test_modules_do_not_count_and_are_brace_matched(self):
        self.crate({
            'lib.rs': 'pub mod a;\npub mod b;\n',
            'b.rs': 'pub struct B;\n',
            'a/mod.rs': '''\
                mod child;
                #[cfg(test)]
                mod more_tests;
                pub struct Thing;
                pub fn run() { child::go(); }
                ''',
            'a/more_tests.rs': 'use super::Thing;\nuse super::child::go;\n',
            'a/child.rs': '''\
                pub fn go() {}

                #[cfg(test)]
                #[allow(unused)]
                mod tests {
                    use super::*;
                    use super::super::Thing;
                    fn f() { if true { let _ = "}"; } }
                }

                pub fn after() -> crate::b::B { crate::b::B }
                ''',
        })
        self.assertEqual(self.upward, set())
        self.assertEqual(self.edges['a::child'], {'b'})  # code after the tests module still counts
        self.assertNotIn('a::more_tests', self.edges)
        self.assertEqual(self.cycles, [])

    def test_reexport_resolves_to_the_declaring_module(self):
        self.crate({
            'lib.rs': 'pub mod p;\n',
            'p/mod.rs': '''\
                pub mod config;
                pub mod scans;
                pub mod stage;
                pub use config::Config as Settings;
                pub use scans::*;
                ''',
            'p/config.rs': 'pub struct Config;\n',
            'p/scans.rs': 'pub const THRESHOLD: f64 = 0.6;\n',
            'p/stage.rs': 'use super::{Settings, THRESHOLD};\nuse crate::p::config;\n',
        })
        self.assertEqual(self.upward, set())
        self.assertEqual(self.edges['p::stage'], {'p::config', 'p::scans'})
        self.assertEqual(self.edges['p'], {'p::config', 'p::scans'})

    def test_glob_import_of_parent_outside_tests_is_upward(self):
        self.crate({
            'lib.rs': 'mod child;\npub struct Root;\n',
            'child.rs': 'use super::*;\n',
        })
        self.assertEqual(self.upward_items(), {('child', 'crate', '*')})

    def test_inline_module_blocks(self):
        self.crate({
            'lib.rs': '''\
                mod inner {
                    pub fn f() {
                        super::g();
                    }
                }
                pub fn g() {
                    inner::f();
                }
                ''',
        })
        self.assertEqual(self.edges['inner'], {'crate'})
        self.assertEqual(self.edges['crate'], {'inner'})
        self.assertEqual(self.upward, {('lib.rs', 3, 'inner', 'crate', 'g')})
        self.assertEqual(self.cycles, [['crate', 'inner']])

    def test_other_crates_and_visibility_paths_are_no_edges(self):
        self.crate({
            'lib.rs': 'pub mod a;\npub mod b;\n',
            'a/mod.rs': 'pub mod init;\n',
            'a/init.rs': '''\
                use roar_ops::init::InitError;
                pub(in crate::b) fn f() -> roar_ops::init::Foo { std::process::exit(0) }
                ''',
            'b.rs': 'pub(crate) fn g() {}\n',
        })
        self.assertEqual(self.edges['a::init'], set())
        self.assertEqual(self.edges['a'], set())

    def test_several_roots_each_checked(self):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        clean, dirty = os.path.join(tmp.name, 'clean'), os.path.join(tmp.name, 'dirty')
        write_tree(clean, {'lib.rs': 'mod a;\npub use a::A;\n', 'a.rs': 'pub struct A;\n'})
        write_tree(dirty, {'lib.rs': 'mod a;\npub struct R;\n', 'a.rs': 'use crate::R;\n'})
        self.assertEqual(run_script(clean)[0], 0)
        code, out = run_script(clean, dirty)
        self.assertEqual(code, 1)
        self.assertIn('== %s\n' % clean, out)
        self.assertIn('== %s\n' % dirty, out)
        self.assertIn('a.rs:1: a -> crate: R', out)
        self.assertIn('1 of 2 roots with cycles or upward imports: %s' % dirty, out)


# The import, `mod` and path lines of crates/roar-cli/src/pipeline/*.rs at e673cf8, each at its
# line number there (`git show e673cf8:crates/roar-cli/src/pipeline/finish.rs` and so on); the
# other lines are left blank, except one stub line per item the children import from `mod.rs`
# (at the line of its definition), and the `#[cfg(test)] mod tests { use super::*; }` blocks.
E673CF8_PIPELINE = {
    'mod.rs': {
        19: 'pub mod config;',
        20: 'mod finish;',
        21: 'mod init;',
        22: 'mod optimize;',
        23: 'mod prepare;',
        24: 'pub mod scans;',
        25: 'pub mod sdf;',
        26: 'pub mod soup;',
        28: 'use std::collections::BTreeMap;',
        29: 'use std::sync::Arc;',
        30: 'use std::sync::atomic::{AtomicBool, Ordering};',
        31: 'use std::time::Instant;',
        33: 'use glam::DVec3;',
        34: 'use roar_loss::{\n'
            '    CoarseViews, KnnOptions, Loss, LossError, PlanarLoss, PlanarOptions, PointCloud, RenderLoss,\n'
            '    Sdf, SdfLoss, SdfLossOptions, Shape, ShapeError, TargetOptions, WeightedSum,\n'
            '};',
        38: 'use roar_mesh::spatial::Projector;',
        39: 'use roar_ops::blocks::block::Block;',
        40: 'use roar_ops::blocks::collapse::{FaceCollapse, FaceCollapseOptions};',
        41: 'use roar_ops::blocks::flips::FlipOptions;',
        42: 'use roar_ops::blocks::smoothing::{SmoothingOptions, TangentialSmoothing};',
        43: 'use roar_ops::blocks::split::{FaceSplit, FaceSplitOptions, SplitThreshold};',
        44: 'use roar_ops::decimate::DecimateError;',
        45: 'use roar_ops::finish::genus::{ReduceGenusError, RemovedHandle};',
        46: 'use roar_ops::init::InitError;',
        47: 'use roar_render::{Camera, Image, star_cameras};',
        48: 'use serde::Serialize;',
        50: 'pub use config::{\n'
            '    FinishConfig, InitConfig, InitKind, LossConfig, OptimizeConfig, ReconstructConfig, TargetConfig,\n'
            '};',
        53: 'pub use scans::{AlignedScans, SCAN_ENCLOSURE_WINDING_THRESHOLD, ScanReport, load_scans};',
        54: 'pub use sdf::SdfShape;',
        55: 'pub use soup::SoupShape;',
        59: 'pub enum PipelineError {}',
        91: "pub struct Prepared<'a> {}",
        110: 'pub type LossFactory = Box<dyn Fn(&Prepared) -> Result<Box<dyn Loss>, PipelineError>>;',
        114: 'pub struct ScheduledBlock {}',
        140: 'pub struct RunStats {}',
        266: 'pub struct IterationRecord {}',
        345: '        let target = prepare::prepare(shape, &mut run)?;',
        346: '        let (mesh, cloud) = init::init(shape, &mut run)?;',
        347: '        let objective = optimize::objective(shape, &target, &cloud, &self.loss_factory, &mut run)?;',
        350: '        let states = optimize::optimize(',
        357: '        let mesh = finish::finish(',
        380: 'pub fn rig_cameras(config: &ReconstructConfig) -> Vec<Camera> {}',
        393: 'pub fn coarse_rig_cameras(config: &ReconstructConfig) -> Vec<Camera> {}',
        415: 'pub fn target_options(config: &ReconstructConfig) -> TargetOptions {}',
        519: 'pub struct UntangleFailure {}',
        528: "struct Run<'a> {}",
        561: 'struct StageClock {}',
        583: '#[cfg(test)]',
        584: 'mod tests {',
        585: '    use super::*;',
        586: '}',
    },
    'finish.rs': {
        8: 'use std::convert::Infallible;',
        10: 'use glam::DVec3;',
        11: 'use roar_loss::{KnnPlanarProjector, Loss};',
        12: 'use roar_mesh::Mesh;',
        13: 'use roar_mesh::spatial::{Normalization, Sdf, self_intersecting_faces};',
        14: 'use roar_ops::blocks::smoothing::SmoothingOptions;',
        15: 'use roar_ops::decimate::{DecimateOptions, DecimateStats, decimate};',
        16: 'use roar_ops::finish::data_flips::{DataFlipOptions, flip_toward_target};',
        17: 'use roar_ops::finish::degenerate::{DegenerateOptions, collapse_degenerate_faces};',
        18: 'use roar_ops::finish::fill::{fill_to_budget, fill_to_budget_on_field};',
        19: 'use roar_ops::finish::fins::{FinOptions, collapse_fins};',
        20: 'use roar_ops::finish::genus::{HandleRemovalOptions, decimate_removing_handles, remove_handles};',
        21: 'use roar_ops::finish::offset::offset_outward;',
        22: 'use roar_ops::finish::slivers::{SliverOptions, flip_slivers};',
        23: 'use roar_ops::finish::zero_set::{ZeroSetOptions, ZeroSetStats, fit_to_zero_set};',
        24: 'use roar_ops::untangle::{UntangleOptions, UntangleStats, untangle};',
        26: 'use super::optimize::{LoopState, move_vertices, new_optimizer};',
        27: 'use super::{PipelineError, ReconstructConfig, Run, RunStats, StageClock, UntangleFailure};',
        515: '#[cfg(test)]',
        516: 'mod tests {',
        517: '    use super::*;',
        518: '    use roar_mesh::EdgeId;',
        519: '    use roar_mesh::shapes::icosphere;',
        520: '    use roar_mesh::spatial::Aabb;',
        521: '    use roar_mesh::spatial::count_intersecting_faces;',
        522: '    use roar_mesh::spatial::triangle_quality;',
        523: '    use roar_ops::finish::fill::bisects_well;',
        524: '    use roar_ops::geometry::{DEGENERATE_QUALITY, is_degenerate};',
        525: '}',
    },
    'init.rs': {
        4: 'use roar_loss::{LossError, PointCloud, Shape};',
        5: 'use roar_mesh::Mesh;',
        6: 'use roar_ops::decimate::{DecimateOptions, decimate};',
        8: 'use super::{InitKind, PipelineError, ReconstructConfig, Run, RunStats};',
        15: '    crate::budget::check_budget(',
        18: '        crate::budget::min_reachable_budget(&mesh.component_genera(), config.finish.keep_topology),',
    },
    'optimize.rs': {
        5: 'use std::borrow::Cow;',
        7: 'use roar_loss::{KnnOptions, KnnPlanarProjector, Loss, LossError, PointCloud, Shape};',
        8: 'use roar_mesh::spatial::Projector;',
        9: 'use roar_mesh::{Mesh, TrackedMesh};',
        10: 'use roar_ops::blocks::block::{BlockContext, BlockStats};',
        11: 'use roar_ops::optim::{Optimizer, OptimizerOptions};',
        12: 'use roar_ops::untangle::{LimiterOptions, limit_steps};',
        13: 'use roar_render::{Camera, Image};',
        15: 'use super::prepare::Target;',
        16: 'use super::{\n'
            '    IterationRecord, LossFactory, PipelineError, Prepared, ReconstructConfig, Run, RunStats,\n'
            '    ScheduledBlock, StageClock, coarse_rig_cameras,\n'
            '};',
        205: 'pub(super) struct LoopState {}',
        212: 'pub(super) fn new_optimizer() {}',
        230: 'pub(super) fn move_vertices() {}',
        286: '#[cfg(test)]',
        287: 'mod tests {',
        288: '    use super::*;',
        289: '}',
    },
    'prepare.rs': {
        4: 'use roar_loss::Shape;',
        5: 'use roar_mesh::spatial::Normalization;',
        6: 'use roar_render::Camera;',
        8: 'use super::{PipelineError, Run, rig_cameras};',
        11: 'pub(super) struct Target {}',
    },
    'config.rs': {
        5: 'use serde::{Deserialize, Serialize};',
        10: 'pub enum InitKind {}',
        24: 'pub struct ReconstructConfig {}',
        456: '    /// [`crate::pipeline::scans::SCAN_ENCLOSURE_WINDING_THRESHOLD`] closing every opening,',
        464: '            crate::pipeline::scans::SCAN_ENCLOSURE_WINDING_THRESHOLD;',
        497: '        crate::budget::check_budget("faces =", self.faces, 4)?;',
        859: '#[cfg(test)]',
        860: 'mod tests {',
        861: '    use super::*;',
        862: '}',
    },
    'scans.rs': {
        7: '//! of the aligned patches, holes and overlaps included, is the target: a '
           '[`crate::pipeline::SoupShape`]',
        13: 'use std::path::Path;',
        15: 'use glam::DVec3;',
        16: 'use roar_io::{IoError, PatchOptions, TriangleSoup};',
        17: 'use roar_ops::align::{AlignOptions, RigidTransform, ScanPatch, align_scans};',
        18: 'use roar_ops::init::ScannerView;',
        19: 'use serde::Serialize;',
        21: 'use super::ReconstructConfig;',
        69: '        let (positions, triangles) = crate::input::drop_unreferenced(&positions, &triangles);',
        169: 'pub const SCAN_ENCLOSURE_WINDING_THRESHOLD: f64 = 0.6;',
    },
    'sdf.rs': {
        11: 'use std::borrow::Cow;',
        12: 'use std::collections::BTreeMap;',
        13: 'use std::sync::{Arc, Mutex};',
        15: 'use roar_loss::{InitialMesh, LossError, PointCloud, Shape, ShapeError};',
        16: 'use roar_mesh::Mesh;',
        17: 'use roar_mesh::spatial::{\n'
            '    Aabb, Normalization, Projector, RIG_RADIUS, Sdf, SdfEvaluations, sample_surface,\n'
            '};',
        20: 'use roar_ops::init::{InitialMeshOptions, SdfInitOptions, initial_mesh_from_init, sdf_init};',
        21: 'use roar_render::{Camera, Image};',
        22: 'use roar_sdf::{RigSdf, SdfProjector, SdfProjectorOptions, TraceOptions, TraceStats};',
        23: 'use serde::Serialize;',
        25: 'use super::ReconstructConfig;',
        50: 'pub struct SdfShape {}',
    },
    'soup.rs': {
        9: 'use std::borrow::Cow;',
        11: 'use glam::DVec3;',
        12: 'use roar_loss::{\n'
            '    InitialMesh, LossError, PointCloud, PointCloudOptions, Shape, ShapeError, ShapeSummary,\n'
            '    SharpEdgeOptions, Target, build_target, point_cloud, render_views, sharp_edge_samples,\n'
            '    two_sided_faces,\n'
            '};',
        17: 'use roar_mesh::Mesh;',
        18: 'use roar_mesh::spatial::{Aabb, Normalization};',
        19: 'use roar_ops::init::{InitOptions, InitialMeshOptions, ScannerView};',
        20: 'use roar_render::{Camera, Image};',
        22: 'use super::{ReconstructConfig, target_options};',
        26: "pub struct SoupShape<'a> {}",
    },
}


class PipelineOfE673cf8(Fixture):
    """The stage modules of `pipeline` import the parent's items, which calls them back."""

    def setUp(self):
        files = {'pipeline/' + name: lines for name, lines in E673CF8_PIPELINE.items()}
        files['lib.rs'] = 'pub mod budget;\npub mod input;\npub mod pipeline;\n'
        files['budget.rs'] = 'pub fn check_budget() {}\npub fn min_reachable_budget() {}\n'
        files['input.rs'] = 'pub fn drop_unreferenced() {}\n'
        self.crate(files)

    def test_upward_imports(self):
        def up(file, line, cur, *items):
            return {('pipeline/' + file, line, 'pipeline::' + cur, 'pipeline', i) for i in items}
        expected = (
            up('finish.rs', 27, 'finish', 'PipelineError', 'Run', 'RunStats', 'StageClock',
               'UntangleFailure')
            | up('init.rs', 8, 'init', 'PipelineError', 'Run', 'RunStats')
            | up('optimize.rs', 17, 'optimize', 'IterationRecord', 'LossFactory',
                 'PipelineError', 'Prepared', 'Run', 'RunStats')
            | up('optimize.rs', 18, 'optimize', 'ScheduledBlock', 'StageClock',
                 'coarse_rig_cameras')
            | up('prepare.rs', 8, 'prepare', 'PipelineError', 'Run', 'rig_cameras')
            | up('soup.rs', 22, 'soup', 'target_options'))
        self.assertEqual(self.upward, expected)

    def test_edges(self):
        p = lambda *names: {'pipeline::' + n for n in names}
        self.assertEqual(self.edges['pipeline'],
                         p('config', 'finish', 'init', 'optimize', 'prepare', 'scans', 'sdf', 'soup'))
        # `ReconstructConfig` is re-exported by `mod.rs` from `config.rs`: an edge to `config`.
        self.assertEqual(self.edges['pipeline::finish'], {'pipeline'} | p('config', 'optimize'))
        self.assertEqual(self.edges['pipeline::init'], {'pipeline', 'budget'} | p('config'))
        self.assertEqual(self.edges['pipeline::optimize'], {'pipeline'} | p('config', 'prepare'))
        self.assertEqual(self.edges['pipeline::prepare'], {'pipeline'})
        self.assertEqual(self.edges['pipeline::config'], {'budget'} | p('scans'))
        self.assertEqual(self.edges['pipeline::scans'], {'input'} | p('config'))
        self.assertEqual(self.edges['pipeline::sdf'], p('config'))
        self.assertEqual(self.edges['pipeline::soup'], {'pipeline'} | p('config'))

    def test_cycles(self):
        self.assertEqual(self.cycles, [
            ['pipeline', 'pipeline::finish', 'pipeline::init', 'pipeline::optimize',
             'pipeline::prepare', 'pipeline::soup'],
            ['pipeline::config', 'pipeline::scans'],
        ])

    def test_report_and_exit_code(self):
        code, out = run_script(self.root)
        self.assertEqual(code, 1)
        self.assertIn("module cycles: [['pipeline', 'pipeline::finish', ", out)
        self.assertIn('pipeline/finish.rs:27: pipeline::finish -> pipeline: PipelineError', out)
        self.assertIn('pipeline/soup.rs:22: pipeline::soup -> pipeline: target_options', out)
        self.assertIn('pipeline -> pipeline::finish  (%s:357 finish::finish)'
                      % os.path.join(self.root, 'pipeline', 'mod.rs'), out)


def have_commit(rev):
    try:
        return subprocess.run(['git', '-C', REPO, 'cat-file', '-e', rev + '^{commit}'],
                              capture_output=True).returncode == 0
    except OSError:
        return False


@unittest.skipUnless(have_commit('e673cf8'), 'commit e673cf8 is not in this repository')
class RealTreeOfE673cf8(unittest.TestCase):
    def test_pipeline_is_in_a_cycle(self):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        tar = subprocess.run(['git', '-C', REPO, 'archive', '--format=tar', 'e673cf8',
                              'crates/roar-cli/src'], capture_output=True, check=True).stdout
        with tarfile.open(fileobj=io.BytesIO(tar)) as t:
            if hasattr(tarfile, 'data_filter'):  # Python 3.11.4 and later
                t.extractall(tmp.name, filter='data')
            else:
                t.extractall(tmp.name)
        root = os.path.join(tmp.name, 'crates', 'roar-cli', 'src')
        code, out = run_script(root)
        self.assertEqual(code, 1, out)
        edges, upward = mc.Crate(root).analyse()
        self.assertTrue(any('pipeline' in c for c in mc.sccs(edges)), out)
        self.assertIn(('pipeline::finish', 'pipeline', 'PipelineError'),
                      {(u[2], u[3], u[4]) for u in upward})


if __name__ == '__main__':
    unittest.main()
