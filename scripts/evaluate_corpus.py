#!/usr/bin/env python3
"""roar and its peers over the corpus manifest (driven by scripts/evaluate_corpus.sh).

Per model and face budget:

- `roar`           through `roar batch OUT/manifest.tsv -o OUT/roar --faces N,…` (resumable:
                   the batch skips items already done by the same build),
- `alphawrap+qem`, `manifold+qem`  scripts/peers.py (the peer once per model, then MeshLab's QEM
                   to every budget), each budget's result recorded in
                   OUT/peers/<method>/<id>/<budget>.json, so a rerun skips it,

and every output measured the same way, by `roar eval OUT --ref RAW_INPUT --json --samples S`
(cached in OUT/eval/<method>/<id>/<budget>.json, keyed by the SHA-256 of the output and of the
measuring binary, `--measure-with`, by default the roar binary). Writes OUT/table.md,
OUT/results.json and OUT/models.tsv after every model.

`--no-run` runs neither roar nor a peer: it measures and tabulates what OUT already holds, so
runs made separately (one budget at a time, in folders linked into one OUT) give one table.

`--paired OLD NEW` instead runs two roar binaries on each model, OLD then NEW, one process at a
time, and writes OUT/paired.md and OUT/paired.json (per-model seconds ratio and Chamfer change).

Every command runs in its own process group; one that passes --timeout is killed by that group
and counts as failed. Stopping the script (Ctrl-C, or SIGTERM to its pid) kills the group of the
command in progress; what that command had not finished is redone by the next run. Standard
library only. How to run it and read the table: docs/evaluation.md, "Dataset table".
"""

import argparse
import csv
import datetime
import hashlib
import json
import os
import re
import signal
import statistics
import subprocess
import sys
import time

METHODS = ["roar", "alphawrap+qem", "manifold+qem"]
PEERS = {"alphawrap+qem": "alphawrap", "manifold+qem": "manifold"}

# Supplementary Table 1 of the paper: % of the 550 ShapeNet models whose output failed (a
# decimation that missed the budget), per budget, as printed there.
PAPER_FAILURES = {
    500: {"ROAR": "10", "Manifold": "5.6", "Manifold+": "8.0"},
    1000: {"ROAR": "6.2", "Manifold": "2.7", "Manifold+": "4.4"},
    5000: {"ROAR": "0.5", "Manifold": "0.18", "Manifold+": "0"},
    10000: {"ROAR": "0", "Manifold": "0", "Manifold+": "0"},
}


class Interrupted(Exception):
    """SIGINT or SIGTERM reached the script."""


def on_signal(signum, _frame):
    raise Interrupted(signal.Signals(signum).name)


def log(message):
    print("[corpus %s] %s" % (time.strftime("%H:%M:%S"), message), file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# Files


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def write_atomic(path, text):
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def write_json(path, value):
    write_atomic(path, json.dumps(value, indent=1))


def sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


# ---------------------------------------------------------------------------------------------
# Commands


def kill_group(proc):
    """Stops `proc` and everything in its process group (it was started as the group's leader):
    SIGTERM, then SIGKILL after 5 s. By pid only, never by name."""
    for sig, grace in ((signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
        try:
            os.killpg(proc.pid, sig)
        except (ProcessLookupError, PermissionError):
            return
        try:
            proc.wait(timeout=grace)
            return
        except subprocess.TimeoutExpired:
            continue


def run(cmd, timeout, log_path=None, capture=True):
    """Runs `cmd` in a new process group. Returns a dict: `stdout`, `wall` and, when it failed,
    `error` (one line) and `timeout` (True when it passed its time limit). Never raises but
    Interrupted, after killing the group."""
    started = time.perf_counter()
    pipe = subprocess.PIPE if capture else None
    try:
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=pipe, stderr=pipe,
                                text=True, start_new_session=True)
    except OSError as e:
        return {"stdout": "", "wall": 0.0, "error": "could not start: %s" % e}
    result = {"stdout": "", "wall": 0.0}
    try:
        stdout, stderr = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        kill_group(proc)
        try:
            stdout, stderr = proc.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            stdout, stderr = "", ""
        result["timeout"] = True
        result["error"] = "timed out after %g s" % timeout
    except BaseException:
        kill_group(proc)
        raise
    result["wall"] = time.perf_counter() - started
    result["stdout"] = stdout or ""
    if log_path:
        write_atomic(log_path, "$ %s\n--- exit %s after %.1f s\n--- stdout\n%s\n--- stderr\n%s" % (
            " ".join(cmd), proc.returncode, result["wall"], stdout or "", stderr or ""))
    if "error" not in result and proc.returncode != 0:
        result["error"] = error_text(stderr or "", proc.returncode)
    return result


def error_text(stderr, returncode):
    """The user-facing part of a failed command's stderr, on one line."""
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    mine = [line for line in lines if line.startswith("roar: error:")]
    if mine:
        lines = [mine[-1][len("roar: error:"):].strip()]
    elif lines:
        lines = lines[-1:]  # a Python traceback or a crash: its last line names the exception
    text = " / ".join(lines) if lines else "no message"
    status = "killed by signal %d" % -returncode if returncode < 0 else "exit %d" % returncode
    return "%s: %s" % (status, text[:400])


# ---------------------------------------------------------------------------------------------
# The models


def read_tsv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader((line for line in f if not line.startswith("#")),
                                   delimiter="\t"))


def read_ids(path):
    """Ids of a subset file: the first tab-separated field of each line ('#' lines, blank
    lines and a header `id` skipped)."""
    ids = []
    with open(path) as f:
        for line in f:
            field = line.split("\t")[0].strip()
            if field and not field.startswith("#") and field != "id":
                ids.append(field)
    return ids


def select(args):
    """The manifest's rows to run, in manifest order, with absolute paths."""
    rows = read_tsv(args.manifest)
    if not rows or "id" not in rows[0] or "path" not in rows[0]:
        sys.exit("%s: a TSV with columns id and path is needed" % args.manifest)
    base = os.path.dirname(os.path.abspath(args.manifest))
    for row in rows:
        row["path"] = os.path.normpath(os.path.join(base, row["path"]))
    wanted = []
    if args.subset:
        wanted.append(read_ids(args.subset))
    if args.ids:
        wanted.append(args.ids.split())
    for ids in wanted:
        known = {row["id"] for row in rows}
        unknown = [i for i in ids if i not in known]
        if unknown:
            sys.exit("not in %s: %s" % (args.manifest, " ".join(unknown)))
        keep = set(ids)
        rows = [row for row in rows if row["id"] in keep]
    if args.limit:
        rows = rows[:args.limit]
    if not rows:
        sys.exit("no model selected")
    return rows


# ---------------------------------------------------------------------------------------------
# Running the methods


def run_roar_batch(args, items):
    """`roar batch` over the selected models at every budget; it skips what is done."""
    manifest = os.path.join(args.out, "manifest.tsv")
    columns = list(items[0].keys())
    text = "\t".join(columns) + "\n" + "".join(
        "\t".join(row.get(c, "") for c in columns) + "\n" for row in items)
    try:
        with open(manifest) as f:
            same = f.read() == text
    except OSError:
        same = False
    if not same:
        write_atomic(manifest, text)
    cmd = [args.roar, "batch", manifest, "-o", os.path.join(args.out, "roar"), "--faces",
           ",".join(str(b) for b in args.budgets), "--jobs", str(args.jobs),
           "--timeout", str(args.timeout)]
    log("roar: %s" % " ".join(cmd))
    # The batch's own time limit is per item and budget; it exits non-zero when any failed.
    outcome = run(cmd, None, capture=False)
    log("roar batch finished in %.0f s%s" % (
        outcome["wall"], "" if "error" not in outcome else " (%s)" % outcome["error"]))


def roar_entry(args, item, budget):
    """roar's result at one budget, from the batch's files."""
    folder = os.path.join(args.out, "roar", item["id"])
    mesh = os.path.join(folder, "%d.obj" % budget)
    record = load_json(os.path.join(folder, "%d.json" % budget))
    if record is not None and os.path.isfile(mesh):
        entry = {"output": mesh, "wall_seconds": record.get("seconds")}
        try:
            stages = record["reconstruct"]["run"]["seconds"]
            # Pipeline time only (the report's stages): no file I/O, no report metrics.
            entry["seconds"] = sum(stages.values())
        except (KeyError, TypeError, AttributeError):
            entry["seconds"] = record.get("seconds")
            entry["note"] = "no stage timings in the report; seconds = wall clock"
        return entry
    failure = load_json(os.path.join(folder, "%d.failure.json" % budget))
    if failure is not None:
        return {"error": failure.get("reason", "failed"), "wall_seconds": failure.get("seconds")}
    return {"missing": True}


def peer_entries(args, item, method):
    """One peer on one model at every budget, run only for budgets without a record."""
    folder = os.path.join(args.out, "peers", method, item["id"])
    path = lambda b: os.path.join(folder, "%d.json" % b)
    records = {b: load_json(path(b)) for b in args.budgets}
    if args.no_run:
        return {b: records[b] or {"missing": True} for b in args.budgets}
    todo = [b for b in args.budgets
            if records[b] is None or ("error" in records[b] and args.retry_failed)]
    if todo:
        os.makedirs(folder, exist_ok=True)
        cmd = [args.python, os.path.join(args.scripts, "peers.py"), PEERS[method], item["path"],
               folder, "--budgets"] + [str(b) for b in todo]
        log("%s %s @ %s" % (method, item["id"], " ".join(map(str, todo))))
        outcome = run(cmd, args.timeout, os.path.join(folder, "peer.log"))
        result = None
        if "error" not in outcome:
            try:
                result = json.loads(outcome["stdout"].strip().splitlines()[-1])
            except (ValueError, IndexError) as e:
                outcome["error"] = "unreadable peer output: %s" % e
        for budget in todo:
            if result is None:
                entry = {"error": outcome["error"]}
            else:
                entry = dict(result["budgets"].get(str(budget),
                                                   {"error": "budget missing in peer output"}))
                for key in ("peer_seconds", "peer_faces", "params", "peak_bytes"):
                    entry[key] = result.get(key)
            entry["wall_seconds"] = outcome["wall"]  # the whole command, every budget in it
            write_json(path(budget), entry)
            records[budget] = entry
    return records


def measure(args, item, method, budget, entry, group="eval"):
    """Adds `metrics` (from `roar eval OUT --ref INPUT`) to an entry with an output."""
    if "output" not in entry:
        return
    output_sha = sha256(entry["output"])
    cache = os.path.join(args.out, group, method, item["id"], "%d.json" % budget)
    cached = load_json(cache)
    if (cached and cached.get("output_sha256") == output_sha
            and cached.get("roar_sha256") == args.measure_sha and cached.get("samples") == args.samples):
        report = cached["report"]
    else:
        cmd = [args.measure_with, "eval", entry["output"], "--ref", item["path"], "--json", "--samples",
               str(args.samples)]
        outcome = run(cmd, args.timeout, cache[:-len(".json")] + ".log")
        try:
            report = json.loads(outcome["stdout"]) if "error" not in outcome else None
        except ValueError as e:
            outcome["error"] = "unreadable: %s" % e
            report = None
        if report is None:
            entry["error"] = "eval failed: %s" % outcome["error"]
            return
        write_json(cache, {"output_sha256": output_sha, "roar_sha256": args.measure_sha,
                           "samples": args.samples, "report": report})
    entry["metrics"] = headline(report, budget)


def headline(report, budget):
    """Validity and fidelity of one output from its `roar eval` report."""
    welded = report.get("topology_welded") or {}
    stored = report.get("topology") or {}
    fidelity = report.get("fidelity") or {}
    si = (report.get("self_intersections") or {}).get("faces")
    faces = stored.get("faces", welded.get("faces"))
    problems = []
    if faces != budget:
        problems.append(("missed the budget", "%s faces" % faces))
    if not (welded.get("watertight") and welded.get("boundary_edges", 1) == 0
            and welded.get("nonmanifold_edges", 1) == 0
            and welded.get("nonmanifold_vertices", 1) == 0):
        problems.append(("not a closed 2-manifold", "%s boundary, %s non-manifold edges, %s "
                         "non-manifold vertices" % (welded.get("boundary_edges"),
                                                    welded.get("nonmanifold_edges"),
                                                    welded.get("nonmanifold_vertices"))))
    if welded.get("inconsistent_edges", 1) != 0:
        problems.append(("not consistently oriented",
                         "%s inconsistent edges" % welded.get("inconsistent_edges")))
    if si is None:
        problems.append(("self-intersections not measured", "no self_intersections in report"))
    elif si > 0:
        problems.append(("self-intersecting faces", "%d faces" % si))
    return {
        "valid": not problems,
        "problems": problems,
        "faces": faces,
        "components": welded.get("components"),
        "genus": welded.get("genus"),
        "self_intersecting_faces": si,
        "chamfer_exact_over_diag": fidelity.get("chamfer_exact_over_diag"),
        "normal_cosine_exact_abs": fidelity.get("normal_cosine_exact_abs"),
        "chamfer_l2_over_diag": fidelity.get("chamfer_l2_over_diag"),
        "signed_volume": (report.get("orientation") or {}).get("signed_volume"),
    }


def error_class(text):
    """A failure's reason, grouped: the kind of failure, numbers and paths taken out."""
    t = text.lower()
    if "timed out" in t:
        return "timed out"
    if "could not decimate" in t:
        return "missed the budget (decimation stopped above it)"
    if "is impossible" in t:
        return "budget below the minimum for the model's pieces"
    if "still intersect" in t:
        return "self-intersections left after the untangle"
    if "killed by signal" in t:
        return re.sub(r":.*", "", text)
    if t.startswith("eval failed"):
        return "eval failed"
    text = re.sub(r"/[^\s:]+", "PATH", text)
    return re.sub(r"\d+(\.\d+)?", "N", text)[:160]


def outcome_of(entry):
    """(status, reasons, detail): status is valid, invalid, failed or missing."""
    if entry.get("missing"):
        return "missing", [], ""
    if "error" in entry:
        return "failed", [error_class(entry["error"])], entry["error"]
    m = entry.get("metrics")
    if m is None:
        return "failed", ["not measured"], ""
    if m["valid"]:
        return "valid", [], ""
    return "invalid", [p[0] for p in m["problems"]], "; ".join(
        "%s (%s)" % p for p in m["problems"])


# ---------------------------------------------------------------------------------------------
# The table


def percentile(values, q):
    """Nearest-rank percentile (q in 0..100) of a non-empty list."""
    values = sorted(values)
    rank = max(1, -(-q * len(values) // 100))
    return values[int(rank) - 1]


def median_or_none(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def summarize(results, methods, budgets):
    models = results["models"]
    out = {}
    for budget in budgets:
        b = str(budget)
        given = lambda m, method: (models[m]["runs"].get(method, {}).get(b) or {}).get("metrics")
        common = [m for m in models if all(given(m, method) for method in methods)]
        per_budget = {"common_models": len(common), "methods": {}}
        for method in methods:
            entries = [(m, models[m]["runs"].get(method, {}).get(b)) for m in models]
            entries = [(m, e) for m, e in entries if e is not None]
            status = {m: outcome_of(e) for m, e in entries}
            valid = sum(1 for s in status.values() if s[0] == "valid")
            failed = sum(1 for s in status.values() if s[0] in ("invalid", "failed"))
            missing = sum(1 for s in status.values() if s[0] == "missing")
            seconds = [e.get("seconds") for _, e in entries
                       if e.get("seconds") is not None and "output" in e]
            row = {
                "models": valid + failed,
                "valid": valid,
                "failed": failed,
                "missing": missing,
                "failed_percent": 100.0 * failed / (valid + failed) if valid + failed else None,
                "median_seconds": statistics.median(seconds) if seconds else None,
                "p90_seconds": percentile(seconds, 90) if seconds else None,
                "median_chamfer_exact_over_diag": median_or_none(
                    [given(m, method)["chamfer_exact_over_diag"] for m in common]),
                "median_normal_cosine_exact_abs": median_or_none(
                    [given(m, method)["normal_cosine_exact_abs"] for m in common]),
                "failures": {},
            }
            for m, e in entries:
                state, reasons, detail = status[m]
                if state == "invalid":  # the reasons are the key: only their figures here
                    detail = "; ".join(p[1] for p in e["metrics"]["problems"])
                if state in ("invalid", "failed"):
                    key = " + ".join(reasons)
                    row["failures"].setdefault(key, []).append({"model": m, "detail": detail})
            if method != "roar" and "roar" in methods:
                pairs = [(given(m, "roar"), given(m, method)) for m in models]
                pairs = [(a["chamfer_exact_over_diag"], p["chamfer_exact_over_diag"])
                         for a, p in pairs if a and p and a["chamfer_exact_over_diag"] is not None
                         and p["chamfer_exact_over_diag"] is not None]
                row["roar_lower_chamfer"] = [sum(1 for a, p in pairs if a < p), len(pairs)]
            per_budget["methods"][method] = row
        out[b] = per_budget
    return out


def fmt(value, kind):
    if value is None:
        return "n/a"
    return {"sci": "%.3e", "cos": "%.4f", "s": "%.1f", "pct": "%.1f %%"}[kind] % value


def cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def write_table(results, methods, budgets, path):
    s = results["summary"]
    lines = ["# roar and its peers on the corpus", ""]
    lines.append("Generated %s by `scripts/evaluate_corpus.sh`: %d models of `%s`%s; every output "
                 "measured by `roar eval OUT --ref RAW_INPUT --json --samples %d`. How to read "
                 "it: docs/evaluation.md, \"Dataset table\"." % (
                     results["started"], len(results["models"]), results["manifest"],
                     " (subset `%s`)" % results["subset"] if results["subset"] else "",
                     results["samples"]))
    lines += ["", "valid = closed, consistently oriented 2-manifold with exactly N faces and no "
              "self-intersecting face. Chamfer/diag and normal cosine: exact (floor-free), medians "
              "over the models where every method gave an output at that budget (*common*). "
              "Seconds: the method's own compute time, medians and p90 over its outputs.", ""]
    lines.append("| method | faces | models | valid | failed | failed % | median s | p90 s "
                 "| common | Chamfer/diag (exact) | abs normal cos (exact) "
                 "| roar lower Chamfer |")
    lines.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for budget in budgets:
        per = s[str(budget)]
        for method in methods:
            r = per["methods"][method]
            beats = r.get("roar_lower_chamfer")
            lines.append("| %s | %d | %d%s | %d | %d | %s | %s | %s | %d | %s | %s | %s |" % (
                method, budget, r["models"],
                " (+%d not run)" % r["missing"] if r["missing"] else "", r["valid"], r["failed"],
                fmt(r["failed_percent"], "pct"), fmt(r["median_seconds"], "s"),
                fmt(r["p90_seconds"], "s"), per["common_models"],
                fmt(r["median_chamfer_exact_over_diag"], "sci"),
                fmt(r["median_normal_cosine_exact_abs"], "cos"),
                "%d of %d" % tuple(beats) if beats else "–"))
    lines += ["", "## Failure rates beside the paper's", "",
              "Paper: supplementary Table 1, 550 ShapeNet models, % of outputs that failed (there: "
              "decimations that missed the budget). Here: % of models whose output is missing or "
              "not valid.", ""]
    lines.append("| faces | " + " | ".join("%s (here)" % m for m in methods)
                 + " | ROAR (paper) | Manifold (paper) | Manifold+ (paper) |")
    lines.append("|---:|" + "---:|" * (len(methods) + 3))
    for budget in budgets:
        per = s[str(budget)]["methods"]
        here = ["%s (%d of %d)" % (fmt(per[m]["failed_percent"], "pct"), per[m]["failed"],
                                   per[m]["models"]) for m in methods]
        paper = PAPER_FAILURES.get(budget)
        theirs = ["%s %%" % paper[k] for k in ("ROAR", "Manifold", "Manifold+")] if paper \
            else ["–"] * 3
        lines.append("| %d | %s | %s |" % (budget, " | ".join(here), " | ".join(theirs)))
    lines += ["", "## Failures by reason", ""]
    rows = []
    for budget in budgets:
        for method in methods:
            for reason, cases in sorted(s[str(budget)]["methods"][method]["failures"].items()):
                shown = ", ".join("%s (%s)" % (c["model"], c["detail"]) if c["detail"]
                                  else c["model"] for c in cases[:10])
                if len(cases) > 10:
                    shown += ", … %d more (results.json)" % (len(cases) - 10)
                rows.append("| %s | %d | %s | %d | %s |" % (method, budget, cell(reason),
                                                              len(cases), cell(shown)))
    if rows:
        lines += ["| method | faces | reason | models | which |", "|---|---:|---|---:|---|"] + rows
    else:
        lines.append("None.")
    lines.append("")
    write_atomic(path, "\n".join(lines))


def write_models_tsv(results, methods, budgets, path):
    lines = ["\t".join(["id", "family", "input_faces", "method", "faces", "status", "reason",
                        "seconds", "wall_seconds", "output_faces", "chamfer_exact_over_diag",
                        "normal_cosine_exact_abs", "chamfer_l2_over_diag"])]
    for name, model in results["models"].items():
        for method in methods:
            for budget in budgets:
                e = model["runs"].get(method, {}).get(str(budget))
                if e is None:
                    continue
                state, _, detail = outcome_of(e)
                m = e.get("metrics") or {}
                value = lambda v: "" if v is None else (("%.6g" % v) if isinstance(v, float)
                                                        else str(v))
                lines.append("\t".join([
                    name, model.get("family", ""), model.get("input_faces", ""), method,
                    str(budget), state, detail.replace("\t", " "), value(e.get("seconds")),
                    value(e.get("wall_seconds")), value(m.get("faces")),
                    value(m.get("chamfer_exact_over_diag")),
                    value(m.get("normal_cosine_exact_abs")), value(m.get("chamfer_l2_over_diag"))]))
    write_atomic(path, "\n".join(lines) + "\n")


def write_outputs(args, results, methods):
    results["summary"] = summarize(results, methods, args.budgets)
    write_json(os.path.join(args.out, "results.json"), results)
    write_table(results, methods, args.budgets, os.path.join(args.out, "table.md"))
    write_models_tsv(results, methods, args.budgets, os.path.join(args.out, "models.tsv"))


def evaluate(args, items, methods):
    results = {
        "started": datetime.datetime.now().isoformat(timespec="seconds"),
        "manifest": args.manifest,
        "subset": args.subset,
        "budgets": args.budgets,
        "methods": methods,
        "samples": args.samples,
        "timeout": args.timeout,
        "roar": args.roar,
        "roar_sha256": args.roar_sha,
        "measured_with": args.measure_with,
        "models": {},
    }
    if "roar" in methods and not args.no_run:
        run_roar_batch(args, items)
    for index, item in enumerate(items, 1):
        runs = {}
        for method in methods:
            if method == "roar":
                runs[method] = {b: roar_entry(args, item, b) for b in args.budgets}
            else:
                runs[method] = peer_entries(args, item, method)
            for budget, entry in runs[method].items():
                measure(args, item, method, budget, entry)
        results["models"][item["id"]] = {
            "family": item.get("family", ""),
            "input_faces": item.get("input_faces", ""),
            "path": item["path"],
            "runs": {m: {str(b): e for b, e in r.items()} for m, r in runs.items()},
        }
        write_outputs(args, results, methods)
        log("%d of %d models measured (%s)" % (index, len(items), item["id"]))
    results["finished"] = datetime.datetime.now().isoformat(timespec="seconds")
    write_outputs(args, results, methods)
    log("wrote %s" % os.path.join(args.out, "table.md"))


# ---------------------------------------------------------------------------------------------
# Paired: two roar binaries


def paired_run(args, item, budget, tag, binary, binary_sha):
    """One `roar reconstruct` of one binary, skipped when its record names the same binary."""
    folder = os.path.join(args.out, "paired", tag, item["id"])
    mesh = os.path.join(folder, "%d.obj" % budget)
    record_path = os.path.join(folder, "%d.json" % budget)
    record = load_json(record_path)
    if record and record.get("binary_sha256") == binary_sha and (
            "error" in record or os.path.isfile(mesh)):
        if "error" not in record or not args.retry_failed:
            return record
    os.makedirs(folder, exist_ok=True)
    report = os.path.join(folder, "%d.report.json" % budget)
    for stale in (mesh, report, record_path):
        if os.path.exists(stale):
            os.remove(stale)
    cmd = [binary, "reconstruct", item["path"], "-o", mesh, "--faces", str(budget), "-q",
           "--report", report]
    log("paired %s %s @ %d" % (tag, item["id"], budget))
    outcome = run(cmd, args.timeout, os.path.join(folder, "%d.log" % budget))
    record = {"binary": binary, "binary_sha256": binary_sha, "wall_seconds": outcome["wall"]}
    if "error" in outcome:
        record["error"] = outcome["error"]
    else:
        record["output"] = mesh
        stages = ((load_json(report) or {}).get("run") or {}).get("seconds")
        if isinstance(stages, dict):
            record["seconds"] = sum(stages.values())
    write_json(record_path, record)
    return record


def paired_summary(results, budgets):
    out = {}
    for budget in budgets:
        b = str(budget)
        rows = []
        for name, model in results["models"].items():
            old, new = model["old"].get(b), model["new"].get(b)
            if old is None or new is None:
                continue
            row = {"model": name, "family": model["family"],
                   "old_valid": outcome_of(old)[0] == "valid",
                   "new_valid": outcome_of(new)[0] == "valid",
                   "old_error": old.get("error"), "new_error": new.get("error"),
                   "old_wall": old.get("wall_seconds"), "new_wall": new.get("wall_seconds")}
            om, nm = old.get("metrics"), new.get("metrics")
            if "error" not in old and "error" not in new and om and nm:
                row["seconds_ratio"] = new["wall_seconds"] / old["wall_seconds"]
                row["old_chamfer"] = om["chamfer_exact_over_diag"]
                row["new_chamfer"] = nm["chamfer_exact_over_diag"]
                row["chamfer_change"] = (nm["chamfer_exact_over_diag"]
                                         / om["chamfer_exact_over_diag"] - 1.0)
                row["normal_change"] = (nm["normal_cosine_exact_abs"]
                                        - om["normal_cosine_exact_abs"])
            rows.append(row)
        both = [r for r in rows if "seconds_ratio" in r]
        ratios = [r["seconds_ratio"] for r in both]
        changes = [r["chamfer_change"] for r in both]
        out[b] = {
            "rows": rows,
            "pairs": len(both),
            "old_valid": sum(r["old_valid"] for r in rows),
            "new_valid": sum(r["new_valid"] for r in rows),
            "median_seconds_ratio": statistics.median(ratios) if ratios else None,
            "p90_seconds_ratio": percentile(ratios, 90) if ratios else None,
            "median_chamfer_change": statistics.median(changes) if changes else None,
            "p90_chamfer_change": percentile(changes, 90) if changes else None,
            "median_normal_change": median_or_none([r["normal_change"] for r in both]),
            "slowest": sorted(both, key=lambda r: -r["seconds_ratio"])[:5],
            "worst_chamfer": sorted(both, key=lambda r: -r["chamfer_change"])[:5],
        }
    return out


def write_paired(args, results):
    results["summary"] = paired_summary(results, args.budgets)
    write_json(os.path.join(args.out, "paired.json"), results)
    pct = lambda v: "n/a" if v is None else "%+.2f %%" % (100 * v)
    ratio = lambda v: "n/a" if v is None else "%.3f" % v
    lines = ["# Two roar builds, paired", "",
             "Generated %s by `scripts/evaluate_corpus.sh --paired`: OLD `%s` (sha256 %s…) then "
             "NEW `%s` (sha256 %s…) on each model, one process at a time; %d models. Seconds: "
             "wall clock of `roar reconstruct` (ratio NEW / OLD; below 1 = NEW faster). Chamfer: "
             "exact Chamfer/diag to the raw input by `roar eval --samples %d` of one binary for "
             "both (change = NEW / OLD − 1; below 0 = NEW closer)." % (
                 results["started"], results["old"], results["old_sha256"][:12], results["new"],
                 results["new_sha256"][:12], len(results["models"]), results["samples"])]
    for budget in args.budgets:
        s = results["summary"][str(budget)]
        lines += ["", "## %d faces" % budget, "",
                  "%d pairs: seconds ratio median %s, p90 %s; Chamfer change median %s, p90 %s; "
                  "normal cosine change median %s. Valid outputs: OLD %d, NEW %d of %d." % (
                      s["pairs"], ratio(s["median_seconds_ratio"]), ratio(s["p90_seconds_ratio"]),
                      pct(s["median_chamfer_change"]), pct(s["p90_chamfer_change"]),
                      "n/a" if s["median_normal_change"] is None
                      else "%+.4f" % s["median_normal_change"],
                      s["old_valid"], s["new_valid"], len(s["rows"])), "",
                  "| model | family | OLD s | NEW s | ratio | OLD Chamfer/diag | NEW Chamfer/diag "
                  "| change | valid OLD / NEW |", "|---|---|---:|---:|---:|---:|---:|---:|---|"]
        for r in s["rows"]:
            if "seconds_ratio" in r:
                lines.append("| %s | %s | %.1f | %.1f | %.3f | %.3e | %.3e | %s | %s / %s |" % (
                    r["model"], r["family"], r["old_wall"], r["new_wall"], r["seconds_ratio"],
                    r["old_chamfer"], r["new_chamfer"], pct(r["chamfer_change"]),
                    "yes" if r["old_valid"] else "**no**", "yes" if r["new_valid"] else "**no**"))
            else:
                lines.append("| %s | %s | | | | %s | %s | | %s / %s |" % (
                    r["model"], r["family"], cell(r["old_error"] or ""),
                    cell(r["new_error"] or ""), "yes" if r["old_valid"] else "**no**",
                    "yes" if r["new_valid"] else "**no**"))
        if s["pairs"]:
            lines += ["", "Slowest (ratio): " + ", ".join(
                "%s %.3f" % (r["model"], r["seconds_ratio"]) for r in s["slowest"]),
                "Worst Chamfer change: " + ", ".join(
                "%s %s" % (r["model"], pct(r["chamfer_change"])) for r in s["worst_chamfer"])]
    lines.append("")
    write_atomic(os.path.join(args.out, "paired.md"), "\n".join(lines))


def paired(args, items):
    old, new = (os.path.abspath(p) for p in args.paired)
    shas = {"old": sha256(old), "new": sha256(new)}
    results = {
        "started": datetime.datetime.now().isoformat(timespec="seconds"),
        "manifest": args.manifest, "subset": args.subset, "budgets": args.budgets,
        "samples": args.samples, "old": old, "new": new, "old_sha256": shas["old"],
        "new_sha256": shas["new"], "evaluator": args.measure_with, "models": {},
    }
    for index, item in enumerate(items, 1):
        model = {"family": item.get("family", ""), "input_faces": item.get("input_faces", ""),
                 "old": {}, "new": {}}
        for budget in args.budgets:
            for tag, binary in (("old", old), ("new", new)):
                entry = dict(paired_run(args, item, budget, tag, binary, shas[tag]))
                measure(args, item, tag, budget, entry, group="paired-eval")
                model[tag][str(budget)] = entry
        results["models"][item["id"]] = model
        write_paired(args, results)
        log("%d of %d models paired (%s)" % (index, len(items), item["id"]))
    results["finished"] = datetime.datetime.now().isoformat(timespec="seconds")
    write_paired(args, results)
    log("wrote %s" % os.path.join(args.out, "paired.md"))


# ---------------------------------------------------------------------------------------------


def main():
    parser = argparse.ArgumentParser(description="roar and its peers over the corpus; "
                                     "see docs/evaluation.md, \"Dataset table\"")
    parser.add_argument("--roar", required=True, help="the roar binary (runs roar, and measures every output unless --measure-with)")
    parser.add_argument("--measure-with", metavar="ROAR",
                        help="the roar binary whose `eval` measures every output (default: --roar); "
                        "a fixed one keeps the measurements cached across roar builds")
    parser.add_argument("--python", help="python of the peers' virtualenv")
    parser.add_argument("--manifest", required=True, help="the corpus manifest (TSV)")
    parser.add_argument("--subset", help="file of ids to take from the manifest")
    parser.add_argument("--ids", help="space-separated ids to take from the manifest")
    parser.add_argument("--limit", type=int, help="only the first K selected models")
    parser.add_argument("--budgets", default="500 1000 5000 10000")
    parser.add_argument("--methods", default=" ".join(METHODS))
    parser.add_argument("--out", default="target/corpus-eval")
    parser.add_argument("--timeout", type=int, default=1800, help="seconds per command")
    parser.add_argument("--jobs", type=int, default=1, help="roar batch --jobs")
    parser.add_argument("--samples", type=int, default=50000, help="roar eval --samples")
    parser.add_argument("--retry-failed", action="store_true",
                        help="rerun the peers' (and --paired runs') recorded failures")
    parser.add_argument("--paired", nargs=2, metavar=("OLD_ROAR", "NEW_ROAR"))
    parser.add_argument("--no-run", action="store_true",
                        help="run neither roar nor a peer: measure and tabulate the outputs "
                        "already in OUT (e.g. budgets run separately, by builds with the same output)")
    args = parser.parse_args()
    args.budgets = [int(b) for b in args.budgets.replace(",", " ").split()]
    args.scripts = os.path.dirname(os.path.abspath(__file__))
    args.out = os.path.abspath(args.out)
    args.roar = os.path.abspath(args.roar)
    args.manifest = os.path.abspath(args.manifest)
    methods = args.methods.split()
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        parser.error("unknown methods %s (known: %s)" % (" ".join(unknown), " ".join(METHODS)))
    if not (args.paired or args.no_run) and any(m in PEERS for m in methods) and not args.python:
        parser.error("--python is needed for the peers")
    items = select(args)
    os.makedirs(args.out, exist_ok=True)
    args.roar_sha = sha256(args.roar)
    args.measure_with = os.path.abspath(args.measure_with or args.roar)
    args.measure_sha = sha256(args.measure_with)
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    try:
        if args.paired:
            log("%d models, budgets %s, paired %s then %s" % (
                len(items), args.budgets, args.paired[0], args.paired[1]))
            paired(args, items)
        else:
            log("%d models, budgets %s, methods %s" % (len(items), args.budgets,
                                                         " ".join(methods)))
            evaluate(args, items, methods)
    except Interrupted as e:
        log("stopped by %s; rerun the same command to resume" % e)
        sys.exit(130)


if __name__ == "__main__":
    main()
