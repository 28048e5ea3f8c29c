#!/usr/bin/env python3
"""Tests of scripts/evaluate_corpus.py and scripts/corpus_subset.py:
`python3 scripts/test_evaluate_corpus.py` (standard library only, a few seconds, no roar)."""
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # no __pycache__ beside the scripts


def load(name, file):
    spec = importlib.util.spec_from_file_location(name, os.path.join(HERE, file))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


ev = load("evaluate_corpus", "evaluate_corpus.py")
sub = load("corpus_subset", "corpus_subset.py")


def report(faces=500, si=0, watertight=True, boundary=0, inconsistent=0):
    welded = {"faces": faces, "watertight": watertight, "boundary_edges": boundary,
              "nonmanifold_edges": 0, "nonmanifold_vertices": 0,
              "inconsistent_edges": inconsistent, "components": 1, "genus": 0}
    return {"topology": dict(welded), "topology_welded": welded,
            "self_intersections": {"faces": si},
            "fidelity": {"chamfer_exact_over_diag": 1e-3, "normal_cosine_exact_abs": 0.9,
                         "chamfer_l2_over_diag": 2e-3}}


class Validity(unittest.TestCase):
    def test_a_closed_oriented_exact_output_without_crossings_is_valid(self):
        self.assertTrue(ev.headline(report(), 500)["valid"])

    def test_each_broken_promise_is_named(self):
        cases = {
            "missed the budget": report(faces=502),
            "self-intersecting faces": report(si=3),
            "not a closed 2-manifold": report(watertight=False, boundary=4),
            "not consistently oriented": report(inconsistent=2),
        }
        for reason, r in cases.items():
            m = ev.headline(r, 500)
            self.assertFalse(m["valid"], reason)
            self.assertEqual([p[0] for p in m["problems"]], [reason])

    def test_a_report_without_self_intersections_is_not_valid(self):
        r = report()
        del r["self_intersections"]
        self.assertFalse(ev.headline(r, 500)["valid"])

    def test_failures_group_by_kind(self):
        self.assertEqual(ev.error_class("timed out after 60 s"), "timed out")
        self.assertEqual(
            ev.error_class("could not decimate to 500 faces: stopped at 612 (112 too many)"),
            "missed the budget (decimation stopped above it)")
        self.assertEqual(ev.error_class("exit 1: /a/b.obj: 12 bad lines"),
                         ev.error_class("exit 1: /c/d.obj: 7 bad lines"))


class Summary(unittest.TestCase):
    def test_percentile_is_nearest_rank(self):
        self.assertEqual(ev.percentile([1, 2, 3, 4, 5, 6, 7, 8, 9, 10], 90), 9)
        self.assertEqual(ev.percentile([5], 90), 5)

    def test_medians_use_models_every_method_gave_and_roar_wins_are_counted(self):
        def entry(chamfer, faces=500):
            r = report(faces=faces)
            r["fidelity"]["chamfer_exact_over_diag"] = chamfer
            return {"output": "x", "seconds": 1.0, "metrics": ev.headline(r, 500)}
        results = {"models": {
            "a": {"runs": {"roar": {"500": entry(1.0)}, "alphawrap+qem": {"500": entry(2.0)}}},
            "b": {"runs": {"roar": {"500": entry(3.0)},
                           "alphawrap+qem": {"500": entry(1.0, faces=510)}}},
            "c": {"runs": {"roar": {"500": entry(5.0)},
                           "alphawrap+qem": {"500": {"error": "timed out after 9 s"}}}},
        }}
        s = ev.summarize(results, ["roar", "alphawrap+qem"], [500])["500"]
        self.assertEqual(s["common_models"], 2)
        roar, peer = s["methods"]["roar"], s["methods"]["alphawrap+qem"]
        self.assertEqual(roar["median_chamfer_exact_over_diag"], 2.0)  # a and b, not c
        self.assertEqual((peer["valid"], peer["failed"]), (1, 2))
        self.assertEqual(peer["roar_lower_chamfer"], [1, 2])
        self.assertEqual(sorted(peer["failures"]), ["missed the budget", "timed out"])


class Commands(unittest.TestCase):
    def test_a_command_past_its_timeout_is_killed_with_its_whole_group(self):
        with tempfile.TemporaryDirectory() as tmp:
            pid_file = os.path.join(tmp, "pid")
            # A shell whose background child would outlive a kill of the shell alone.
            cmd = ["sh", "-c", "sleep 60 & echo $! > %s; wait" % pid_file]
            started = time.time()
            outcome = ev.run(cmd, 1, os.path.join(tmp, "log"))
            self.assertLess(time.time() - started, 20)
            self.assertTrue(outcome.get("timeout"))
            self.assertEqual(outcome["error"], "timed out after 1 s")
            with open(pid_file) as f:
                grandchild = int(f.read())
            time.sleep(0.2)
            try:
                os.kill(grandchild, 0)
                alive = open("/proc/%d/stat" % grandchild).read().split()[2] != "Z"
            except (ProcessLookupError, FileNotFoundError):
                alive = False
            self.assertFalse(alive, "the group's other process survived")

    def test_a_hung_peer_is_recorded_as_timed_out_and_not_run_again(self):
        with tempfile.TemporaryDirectory() as tmp:
            runs = os.path.join(tmp, "runs")
            fake = os.path.join(tmp, "python")  # stands in for the venv's python + peers.py
            with open(fake, "w") as f:
                f.write("#!/bin/sh\necho run >> %s\nsleep 60\n" % runs)
            os.chmod(fake, 0o755)
            args = type("Args", (), dict(out=tmp, budgets=[500, 1000], python=fake,
                                         scripts=HERE, timeout=1, retry_failed=False,
                                         no_run=False))()
            item = {"id": "m", "path": "/nonexistent.obj"}
            first = ev.peer_entries(args, item, "manifold+qem")
            self.assertEqual({b: e["error"] for b, e in first.items()},
                             {500: "timed out after 1 s", 1000: "timed out after 1 s"})
            again = ev.peer_entries(args, item, "manifold+qem")
            self.assertEqual(again[500]["error"], "timed out after 1 s")
            with open(runs) as f:
                self.assertEqual(f.read().split(), ["run"])  # the second call ran nothing
            args.retry_failed = True
            ev.peer_entries(args, item, "manifold+qem")
            with open(runs) as f:
                self.assertEqual(f.read().split(), ["run", "run"])

    def test_roar_batch_files_become_entries(self):
        with tempfile.TemporaryDirectory() as tmp:
            folder = os.path.join(tmp, "roar", "m")
            os.makedirs(folder)
            ev.write_json(os.path.join(folder, "500.failure.json"), {
                "id": "m", "budget": 500, "seconds": 3.0,
                "reason": "could not decimate to 500 faces: stopped at 612 (112 too many)"})
            with open(os.path.join(folder, "1000.obj"), "w") as f:
                f.write("")
            ev.write_json(os.path.join(folder, "1000.json"), {
                "seconds": 9.0, "reconstruct": {"run": {"seconds": {"init": 2.0, "loop": 5.0}}}})
            args = type("Args", (), dict(out=tmp))()
            item = {"id": "m"}
            failed = ev.roar_entry(args, item, 500)
            self.assertEqual(ev.outcome_of(failed)[:2],
                             ("failed", ["missed the budget (decimation stopped above it)"]))
            done = ev.roar_entry(args, item, 1000)
            self.assertEqual((done["seconds"], done["wall_seconds"]), (7.0, 9.0))
            self.assertEqual(ev.outcome_of(ev.roar_entry(args, item, 5000))[0], "missing")

    def test_measurements_are_kept_while_the_measuring_binary_is_the_same(self):
        with tempfile.TemporaryDirectory() as tmp:
            calls = os.path.join(tmp, "calls")
            fake = os.path.join(tmp, "roar")  # `roar eval ... --json`: one valid report
            with open(fake, "w") as f:
                f.write("#!/bin/sh\necho eval >> %s\necho '%s'\n" % (
                    calls, json.dumps(report())))
            os.chmod(fake, 0o755)
            output = os.path.join(tmp, "out.obj")
            with open(output, "w") as f:
                f.write("v 0 0 0\n")
            args = type("Args", (), dict(out=tmp, measure_with=fake, measure_sha=ev.sha256(fake),
                                         samples=100, timeout=10))()
            item = {"id": "m", "path": "/input.obj"}
            for _ in range(2):  # a new roar build changes neither the output nor the measurer
                entry = {"output": output}
                ev.measure(args, item, "manifold+qem", 500, entry)
                self.assertTrue(entry["metrics"]["valid"])
            with open(calls) as f:
                self.assertEqual(f.read().split(), ["eval"])
            args.measure_sha = "another measuring binary"
            ev.measure(args, item, "manifold+qem", 500, {"output": output})
            with open(calls) as f:
                self.assertEqual(f.read().split(), ["eval", "eval"])

    def test_no_run_tabulates_the_outputs_already_there_and_runs_nothing(self):
        with tempfile.TemporaryDirectory() as tmp:
            fake = os.path.join(tmp, "fake-roar")  # only `roar eval` may be called: one valid report
            with open(fake, "w") as f:
                f.write("#!/bin/sh\n[ \"$1\" = eval ] || exit 3\necho '%s'\n" % json.dumps(report()))
            os.chmod(fake, 0o755)
            folder = os.path.join(tmp, "roar", "m")
            os.makedirs(folder)
            with open(os.path.join(folder, "500.obj"), "w") as f:
                f.write("v 0 0 0\n")
            ev.write_json(os.path.join(folder, "500.json"), {
                "seconds": 4.0, "reconstruct": {"run": {"seconds": {"init": 1.0, "loop": 2.0}}}})
            peer = os.path.join(tmp, "peers", "manifold+qem", "m")
            os.makedirs(peer)
            with open(os.path.join(peer, "500.obj"), "w") as f:
                f.write("v 1 0 0\n")
            ev.write_json(os.path.join(peer, "500.json"), {"output": os.path.join(peer, "500.obj"),
                                                         "seconds": 1.0})
            args = type("Args", (), dict(
                out=tmp, no_run=True, python="/no/python", scripts=HERE, roar=fake, roar_sha="x",
                measure_with=fake, measure_sha=ev.sha256(fake), samples=100, timeout=10,
                budgets=[500, 1000], retry_failed=False, manifest="m.tsv", subset=None))()
            ev.evaluate(args, [{"id": "m", "path": "/input.obj"}], ["roar", "manifold+qem"])
            with open(os.path.join(tmp, "results.json")) as f:
                summary = json.load(f)["summary"]
            for method in ("roar", "manifold+qem"):
                self.assertEqual(summary["500"]["methods"][method]["valid"], 1)
                self.assertEqual(summary["1000"]["methods"][method]["missing"], 1)
            self.assertEqual(summary["500"]["methods"]["roar"]["median_seconds"], 3.0)
            self.assertFalse(os.path.exists(os.path.join(tmp, "manifest.tsv")))  # no batch ran

    def test_a_failing_command_reports_its_last_line(self):
        outcome = ev.run(["sh", "-c", "echo noise >&2; echo 'roar: error: no budget' >&2; exit 3"],
                         10)
        self.assertEqual(outcome["error"], "exit 3: no budget")


class Subset(unittest.TestCase):
    def test_small_families_keep_their_floor_and_the_rest_is_proportional(self):
        share = sub.allocate({"cad": 17, "furniture": 228, "organic": 5}, 50, 5)
        self.assertEqual(share, {"cad": 7, "furniture": 38, "organic": 5})
        self.assertEqual(sum(sub.allocate({"a": 3, "b": 100}, 20, 5).values()), 20)

    def test_picks_spread_over_sizes_and_do_not_depend_on_order(self):
        rows = [{"id": "m%02d" % i, "input_faces": str(10 * i)} for i in range(20)]
        picked = [r["id"] for r in sub.pick(rows, 4)]
        self.assertEqual(picked, ["m02", "m07", "m12", "m17"])
        self.assertEqual([r["id"] for r in sub.pick(list(reversed(rows)), 4)], picked)

    def test_the_committed_subset_lists_fifty_ids(self):
        ids = ev.read_ids(os.path.join(HERE, "corpus-subset-50.tsv"))
        self.assertEqual(len(ids), 50)
        self.assertEqual(len(set(ids)), 50)

    def test_the_subset_is_regenerated_byte_for_byte_when_the_corpus_is_there(self):
        data = os.environ.get("ROAR_TEST_DATA") or os.path.join(HERE, "..", "..", "shared",
                                                                "data", "meshes")
        manifest = os.path.join(data, "..", "corpus", "manifest.tsv")
        if not os.path.isfile(manifest):
            self.skipTest("no corpus manifest at %s" % manifest)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "subset.tsv")
            subprocess.run([sys.executable, os.path.join(HERE, "corpus_subset.py"), "--manifest",
                            manifest, "-o", out], check=True, capture_output=True)
            with open(out) as a, open(os.path.join(HERE, "corpus-subset-50.tsv")) as b:
                self.assertEqual(a.read(), b.read())


if __name__ == "__main__":
    unittest.main()
