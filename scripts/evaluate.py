#!/usr/bin/env python3
"""Side-by-side evaluation of roar against its peers (driven by scripts/evaluate.sh).

For every input mesh and face budget it makes four outputs:

- `roar`          `roar reconstruct --faces N` (the full pipeline),
- `roar-init+qem` `roar reconstruct --faces N --iterations 0` (roar's own init, decimated),
- `alphawrap+qem` CGAL alpha wrap (diag/300, offset diag/1000) then MeshLab QEM to N,
- `manifold+qem`  Manifold (point-cloud-utils, resolution 20000) then MeshLab QEM to N,

measures each with `roar eval --json --ref RAW_INPUT --samples S` (the same sampling for all
methods), and writes `OUT/results.json` (every number) and `OUT/table.md` (one table per budget
and a summary). Both files are rewritten after every mesh, so a long run shows its progress.
A method that crashes, times out or misses its budget becomes a row with its error text; the
run goes on. Standard library only: runs under any Python 3.8+.
"""

import argparse
import datetime
import glob
import json
import os
import statistics
import subprocess
import sys
import time

METHODS = ["roar", "roar-init+qem", "alphawrap+qem", "manifold+qem"]
PEERS = {"alphawrap+qem": "alphawrap", "manifold+qem": "manifold"}


def log(message):
    print("[evaluate %s] %s" % (time.strftime("%H:%M:%S"), message), file=sys.stderr, flush=True)


def error_text(stderr, returncode):
    """The user-facing part of a failed command's stderr, on one line."""
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    # roar prints its whole error chain as one `roar: error: ...` line.
    start = next((i for i, line in enumerate(lines) if line.startswith("roar: error:")), None)
    if start is not None:
        lines = [lines[start][len("roar: error:"):].strip()]
    elif lines:
        lines = lines[-1:]  # a Python traceback or a crash: its last line names the exception
    text = " / ".join(lines) if lines else "no message"
    status = "killed by signal %d" % -returncode if returncode < 0 else "exit %d" % returncode
    return "%s: %s" % (status, text[:400])


def run(cmd, timeout, log_path):
    """Runs `cmd`; returns (stdout, error or None, wall seconds). Never raises."""
    started = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "", "timeout after %d s" % timeout, time.perf_counter() - started
    except OSError as e:
        return "", "could not start: %s" % e, time.perf_counter() - started
    wall = time.perf_counter() - started
    with open(log_path, "w") as out:
        out.write("$ %s\n--- stdout\n%s\n--- stderr\n%s" % (" ".join(cmd), proc.stdout, proc.stderr))
    if proc.returncode != 0:
        return proc.stdout, error_text(proc.stderr, proc.returncode), wall
    return proc.stdout, None, wall


def roar_runs(args, mesh, workdir, iterations, method):
    """`roar reconstruct` at every budget; entries with output path and seconds or an error."""
    entries = {}
    os.makedirs(workdir, exist_ok=True)
    for budget in args.budgets:
        output = os.path.join(workdir, "%d.obj" % budget)
        report = os.path.join(workdir, "%d.report.json" % budget)
        for stale in (output, report):
            if os.path.exists(stale):
                os.remove(stale)
        cmd = [args.roar, "reconstruct", mesh, "-o", output, "--faces", str(budget), "-q",
               "--report", report]
        if iterations is not None:
            cmd += ["--iterations", str(iterations)]
        log("%s %s @ %d" % (method, os.path.basename(mesh), budget))
        _, error, wall = run(cmd, args.timeout, os.path.join(workdir, "%d.log" % budget))
        entry = {"wall_seconds": wall}
        if error:
            entry["error"] = error
        else:
            entry["output"] = output
            entry["seconds"] = wall
            try:
                with open(report) as f:
                    stages = json.load(f)["run"]["seconds"]
                # Pipeline time only: the report's own metrics and file I/O are not counted.
                entry["seconds"] = sum(stages.values())
                entry["stage_seconds"] = stages
            except (OSError, KeyError, ValueError, AttributeError) as e:
                entry["note"] = "no stage timings in report (%s); seconds = wall clock" % e
        entries[budget] = entry
    return entries


def peer_runs(args, mesh, workdir, method):
    """One peer on one mesh, decimated to every budget (one subprocess for all budgets)."""
    os.makedirs(workdir, exist_ok=True)
    cmd = [args.python, os.path.join(args.scripts, "peers.py"), PEERS[method], mesh, workdir,
           "--budgets"] + [str(b) for b in args.budgets]
    log("%s %s" % (method, os.path.basename(mesh)))
    stdout, error, wall = run(cmd, args.timeout, os.path.join(workdir, "peer.log"))
    if error:
        return {b: {"error": error, "wall_seconds": wall} for b in args.budgets}
    try:
        result = json.loads(stdout.strip().splitlines()[-1])
    except (ValueError, IndexError) as e:
        return {b: {"error": "unreadable peer output: %s" % e} for b in args.budgets}
    entries = {}
    for budget in args.budgets:
        entry = dict(result["budgets"].get(str(budget), {"error": "budget missing in output"}))
        entry["peer_seconds"] = result.get("peer_seconds")
        entry["peer_faces"] = result.get("peer_faces")
        entry["params"] = result.get("params")
        entries[budget] = entry
    return entries


def measure(args, mesh, entry, log_path):
    """Adds `roar eval` metrics (against the raw input) to a successful entry."""
    if "error" in entry:
        return
    cmd = [args.roar, "eval", entry["output"], "--ref", mesh, "--json", "--samples",
           str(args.samples)]
    stdout, error, _ = run(cmd, args.timeout, log_path)
    if error:
        entry["error"] = "eval failed: " + error
        return
    try:
        entry["eval"] = json.loads(stdout)
    except ValueError as e:
        entry["error"] = "eval output unreadable: %s" % e
        return
    entry["metrics"] = headline(entry["eval"])
    budget_faces = entry.get("budget")
    if budget_faces and entry["metrics"]["faces"] != budget_faces:
        entry.setdefault("note", "%d faces, budget %d" % (entry["metrics"]["faces"], budget_faces))


def headline(report):
    """The table's numbers from one `roar eval` report (None where a metric is absent)."""
    welded = report.get("topology_welded", {})
    fidelity = report.get("fidelity") or {}
    intersections = report.get("self_intersections")
    return {
        "closed_manifold": bool(
            welded.get("watertight")
            and welded.get("boundary_edges", 1) == 0
            and welded.get("nonmanifold_edges", 1) == 0
            and welded.get("nonmanifold_vertices", 1) == 0
        ),
        "components": welded.get("components"),
        "faces": welded.get("faces"),
        "self_intersecting_faces": intersections.get("faces") if intersections else None,
        "chamfer_over_diag": fidelity.get("chamfer_l2_over_diag"),
        "normal_cosine_abs": fidelity.get("normal_cosine_abs"),
        "hausdorff_over_diag": fidelity.get("hausdorff_over_diag"),
        "aspect_ratio_median": report.get("quality", {}).get("aspect_ratio_median"),
        "signed_volume": report.get("orientation", {}).get("signed_volume"),
    }


# ---------------------------------------------------------------------------------------------
# Output


def fmt(value, kind):
    if value is None:
        return "n/a"
    if kind == "bool":
        return "yes" if value else "**no**"
    if kind == "int":
        return str(value)
    if kind == "sci":
        return "%.3e" % value
    if kind == "cos":
        return "%.4f" % value
    if kind == "f2":
        return "%.2f" % value
    if kind == "s":
        return "%.1f" % value
    return str(value)


def cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def median_or_none(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def summary(results, budget):
    """Per-budget comparison figures (see docs/evaluation.md for how to read them)."""
    meshes = results["meshes"]

    def metric(mesh, method, key):
        entry = meshes[mesh].get(method, {}).get(str(budget), {})
        return (entry.get("metrics") or {}).get(key) if "error" not in entry else None

    out = {"meshes": len(meshes)}
    for peer in ("roar-init+qem", "alphawrap+qem", "manifold+qem"):
        for key, better in (("chamfer_over_diag", lambda a, b: a < b),
                            ("normal_cosine_abs", lambda a, b: a > b)):
            pairs = [(metric(m, "roar", key), metric(m, peer, key)) for m in meshes]
            pairs = [(a, b) for a, b in pairs if a is not None and b is not None]
            out["roar_beats_%s_%s" % (peer, key)] = [sum(better(a, b) for a, b in pairs), len(pairs)]
    ratios = [metric(m, "roar", "chamfer_over_diag") / metric(m, "roar-init+qem", "chamfer_over_diag")
              for m in meshes
              if metric(m, "roar", "chamfer_over_diag") is not None
              and metric(m, "roar-init+qem", "chamfer_over_diag")]
    out["roar_over_init_chamfer_median_ratio"] = median_or_none(ratios)
    for method in METHODS:
        entries = [meshes[m][method][str(budget)] for m in meshes
                   if str(budget) in meshes[m].get(method, {})]
        out["median_seconds_" + method] = median_or_none(
            [e.get("seconds") for e in entries if "error" not in e])
        # None (printed n/a) when the method was not run at all (--methods).
        out["failures_" + method] = sum(1 for e in entries if "error" in e) if entries else None
    return out


def write_table(results, path):
    lines = ["# roar vs peers", ""]
    lines.append("Generated %s by `scripts/evaluate.sh` (roar iterations: %s, eval samples: %d). "
                 "Metrics from `roar eval --ref RAW_INPUT`; see docs/evaluation.md." % (
                     results["started"], results["iterations"] or "default", results["samples"]))
    header = ("| mesh | method | closed 2-manifold | components | faces | self-int. faces "
              "| Chamfer/diag | abs normal cos | median aspect | seconds |")
    for budget in results["budgets"]:
        lines += ["", "## %d faces" % budget, "", header, "|" + "---|" * 10]
        for mesh, methods in results["meshes"].items():
            for method in METHODS:
                entry = methods.get(method, {}).get(str(budget))
                if entry is None:
                    continue
                if "error" in entry:
                    lines.append("| %s | %s | **failed**: %s |  |  |  |  |  |  |  |" % (
                        cell(mesh), method, cell(entry["error"])))
                    continue
                m = entry["metrics"]
                lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                    cell(mesh), method, fmt(m["closed_manifold"], "bool"),
                    fmt(m["components"], "int"), fmt(m["faces"], "int"),
                    fmt(m["self_intersecting_faces"], "int"), fmt(m["chamfer_over_diag"], "sci"),
                    fmt(m["normal_cosine_abs"], "cos"), fmt(m["aspect_ratio_median"], "f2"),
                    fmt(entry.get("seconds"), "s")))
        s = results["summary"][str(budget)]
        lines += ["", "### Summary at %d faces (%d meshes)" % (budget, s["meshes"]), ""]
        lines += ["| roar vs | Chamfer: roar better | normal cosine: roar better |", "|---|---|---|"]
        for peer in ("roar-init+qem", "alphawrap+qem", "manifold+qem"):
            c = s["roar_beats_%s_chamfer_over_diag" % peer]
            n = s["roar_beats_%s_normal_cosine_abs" % peer]
            lines.append("| %s | %d of %d | %d of %d |" % (peer, c[0], c[1], n[0], n[1]))
        ratio = s["roar_over_init_chamfer_median_ratio"]
        lines += ["", "- median Chamfer ratio roar / roar-init+qem: %s" % (
            "n/a" if ratio is None else "%.3f" % ratio)]
        lines.append("- median seconds: " + ", ".join(
            "%s %s" % (m, fmt(s["median_seconds_" + m], "s")) for m in METHODS))
        lines.append("- failures: " + ", ".join(
            "%s %s" % (m, fmt(s["failures_" + m], "int")) for m in METHODS))
    lines.append("")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines))
    os.replace(tmp, path)


def write_json(results, path):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(results, f, indent=1, sort_keys=False)
    os.replace(tmp, path)


# ---------------------------------------------------------------------------------------------


def earlier_rows(path, args, methods):
    """Rows of methods not run now, from an earlier run into the same folder with the same
    budgets and sample count, so the peers and roar can be run (and rerun) separately."""
    try:
        with open(path) as f:
            earlier = json.load(f)
    except (OSError, ValueError):
        return {}
    if earlier.get("budgets") != args.budgets or earlier.get("samples") != args.samples:
        log("not keeping rows of %s: other budgets or sample count" % path)
        return {}
    kept = {}
    for name, per_method in earlier.get("meshes", {}).items():
        rows = {m: e for m, e in per_method.items() if m not in methods}
        if rows:
            kept[name] = rows
    if kept:
        log("keeping rows of %s from %s" % (
            " ".join(sorted({m for r in kept.values() for m in r})), path))
    return kept


def main():
    parser = argparse.ArgumentParser(description="roar vs peers; see docs/evaluation.md")
    parser.add_argument("--roar", required=True, help="the roar binary")
    parser.add_argument("--python", required=True, help="python of the peers' virtualenv")
    parser.add_argument("--data", required=True, help="folder of input meshes")
    parser.add_argument("--meshes", default="*", help="space-separated globs of file names inside --data (or paths)")
    parser.add_argument("--budgets", default="1000 5000")
    parser.add_argument("--iterations", type=int, default=None)
    parser.add_argument("--samples", type=int, default=50000)
    parser.add_argument("--timeout", type=int, default=3600, help="seconds per command")
    parser.add_argument("--methods", default=" ".join(METHODS))
    parser.add_argument("--out", required=True)
    parser.add_argument("--keep-from", action="append", default=[], metavar="DIR",
                        help="also keep rows of methods not run now from DIR/results.json")
    args = parser.parse_args()
    args.budgets = [int(b) for b in args.budgets.split()]
    args.scripts = os.path.dirname(os.path.abspath(__file__))
    methods = args.methods.split()
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        parser.error("unknown methods %s (known: %s)" % (unknown, " ".join(METHODS)))

    patterns = [p if os.sep in p else os.path.join(args.data, p) for p in args.meshes.split()]
    meshes = sorted({p for pattern in patterns for p in glob.glob(pattern) if os.path.isfile(p)})
    if not meshes:
        sys.exit("no mesh matches %s" % " ".join(patterns))
    os.makedirs(args.out, exist_ok=True)
    results = {
        "started": datetime.datetime.now().isoformat(timespec="seconds"),
        "budgets": args.budgets,
        "iterations": args.iterations,
        "samples": args.samples,
        "roar": args.roar,
        "meshes": {},
    }
    kept = {}
    for folder in [args.out] + args.keep_from:
        for name, rows in earlier_rows(os.path.join(folder, "results.json"), args, methods).items():
            kept.setdefault(name, {}).update(rows)
    log("%d meshes, budgets %s, methods %s" % (len(meshes), args.budgets, " ".join(methods)))
    for mesh in meshes:
        name = os.path.basename(mesh)
        work = os.path.join(args.out, "meshes", name)
        per_method = dict(kept.get(name, {}))
        for method in methods:
            workdir = os.path.join(work, method)
            if method == "roar":
                entries = roar_runs(args, mesh, workdir, args.iterations, method)
            elif method == "roar-init+qem":
                entries = roar_runs(args, mesh, workdir, 0, method)
            else:
                entries = peer_runs(args, mesh, workdir, method)
            for budget, entry in entries.items():
                entry["budget"] = budget
                measure(args, mesh, entry, os.path.join(workdir, "%d.eval.log" % budget))
            per_method[method] = {str(b): e for b, e in entries.items()}
        results["meshes"][name] = per_method
        results["summary"] = {str(b): summary(results, b) for b in args.budgets}
        write_json(results, os.path.join(args.out, "results.json"))
        write_table(results, os.path.join(args.out, "table.md"))
    results["finished"] = datetime.datetime.now().isoformat(timespec="seconds")
    write_json(results, os.path.join(args.out, "results.json"))
    log("wrote %s and %s" % (os.path.join(args.out, "table.md"),
                             os.path.join(args.out, "results.json")))


if __name__ == "__main__":
    main()
