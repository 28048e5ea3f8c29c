#!/usr/bin/env python3
"""The work of scripts/evaluate_sdf.sh (read its header): roar against the marching baseline on
SDF inputs, every output measured against the reference surface; writes OUT/table.md and
OUT/results.json."""

import argparse
import json
import os
import subprocess
import sys

from roar_runs import evaluate, timed


def extract(roar, field, mesh, resolution, bounds):
    """`roar extract`; returns its JSON line plus seconds and peak bytes, kept in MESH.json so that
    the reference's extraction serves as its resolution's row and a rerun resumes."""
    info_path = mesh + ".json"
    if os.path.exists(mesh) and os.path.exists(info_path):
        with open(info_path) as f:
            return json.load(f)
    cmd = [roar, "extract", field, "-o", mesh, "--resolution", str(resolution), "--json"]
    if bounds:
        cmd += ["--bounds", bounds]
    proc, seconds, peak = timed(cmd)
    if proc.returncode != 0:
        sys.exit("extract failed: " + proc.stderr.strip().splitlines()[-1])
    line = json.loads(proc.stdout.strip().splitlines()[-1])
    line.update(seconds=seconds, peak_bytes=peak)
    with open(info_path, "w") as f:
        json.dump(line, f)
    return line


def meshlab_rows(a, name, resolution, grid, info, ref):
    """The rows of one extraction decimated by MeshLab's QEM instead of roar's: `peers.py qem`
    (topology-preserving quadric edge collapse) run by the `--meshlab` python, once for every
    budget the grid reaches."""
    method = "marching tetrahedra %d³ + MeshLab QEM" % resolution
    budgets = [n for n in a.budgets if info["faces"] >= n]
    result = {"budgets": {}}
    if budgets:
        peers = os.path.join(os.path.dirname(os.path.abspath(__file__)), "peers.py")
        outdir = os.path.join(a.out, "%s-mt-%d-meshlab" % (name, resolution))
        cmd = [a.meshlab, peers, "qem", grid, outdir, "--budgets"] + [str(n) for n in budgets]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode == 0:
            result = json.loads(proc.stdout.strip().splitlines()[-1])
        else:
            failure = (proc.stderr.strip() or "failed").splitlines()[-1]
            result["budgets"] = {str(n): {"error": failure} for n in budgets}
    rows = []
    for n in a.budgets:
        row = {"field": name, "method": method, "budget": n,
               "values": info["values"], "gradients": info["gradients"]}
        entry = result["budgets"].get(str(n))
        if entry is None:
            row["error"] = "the grid gives %d faces, under the budget" % info["faces"]
        elif "error" in entry:
            row["error"] = entry["error"]
        else:
            row["seconds"] = info["seconds"] + entry["qem_seconds"]
            row["peak_bytes"] = max(info["peak_bytes"] or 0, result.get("peak_bytes") or 0)
            row.update(evaluate(a.roar, entry["output"], ref, a.samples))
        print(row, file=sys.stderr)
        rows.append(row)
    return rows


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--roar", required=True)
    p.add_argument("--fields", nargs="+", required=True)
    p.add_argument("--budgets", nargs="+", type=int, required=True)
    p.add_argument("--resolutions", nargs="+", type=int, required=True)
    p.add_argument("--reference", type=int, required=True)
    p.add_argument("--refs", nargs="*", default=[],
                   help="reference meshes, one per field, in place of the fields' extractions")
    p.add_argument("--config", default="")
    p.add_argument("--bounds", default="")
    p.add_argument("--samples", type=int, required=True)
    p.add_argument("--meshlab", default="", help="a python with pymeshlab: adds MeshLab QEM rows")
    p.add_argument("--out", required=True)
    a = p.parse_args()
    if a.refs and len(a.refs) != len(a.fields):
        sys.exit("evaluate_sdf: --refs needs one mesh per field")
    rows = []
    for k, field in enumerate(a.fields):
        name = os.path.basename(field).split(".")[0]
        ref = a.refs[k] if a.refs else os.path.join(a.out, "%s-mt-%d.obj" % (name, a.reference))
        if not os.path.exists(ref):
            info = extract(a.roar, field, ref, a.reference, a.bounds)
            print("%s: reference %d³ %.0f s, %d faces" % (name, a.reference, info["seconds"], info["faces"]),
                  file=sys.stderr)
        for n in a.budgets:
            mesh = os.path.join(a.out, "%s-roar-%d.obj" % (name, n))
            report = os.path.join(a.out, "%s-roar-%d.json" % (name, n))
            cmd = [a.roar, "reconstruct", field, "-o", mesh, "--faces", str(n), "-q", "--report", report]
            if a.config:
                cmd += ["--config", a.config]
            if a.bounds:
                cmd += ["--bounds", a.bounds]
            timing = report + ".time"
            if os.path.exists(mesh) and os.path.exists(report) and os.path.exists(timing):
                # A finished run of an earlier invocation (the script resumes).
                with open(timing) as f:
                    seconds, peak = json.load(f)
                ok, error = True, ""
            else:
                proc, seconds, peak = timed(cmd)
                ok, error = proc.returncode == 0, proc.stderr.strip()
                if ok:
                    with open(timing, "w") as f:
                        json.dump([seconds, peak], f)
            row = {"field": name, "method": "roar", "budget": n, "seconds": seconds, "peak_bytes": peak}
            if not ok:
                row["error"] = error.splitlines()[-1] if error else "failed"
            else:
                with open(report) as f:
                    sdf = json.load(f)["sdf"]
                row["values"] = sum(sdf["values"].values())
                row["gradients"] = sum(sdf["gradients"].values())
                row.update(evaluate(a.roar, mesh, ref, a.samples))
            print(row, file=sys.stderr)
            rows.append(row)
        for r in a.resolutions:
            grid = os.path.join(a.out, "%s-mt-%d.obj" % (name, r))
            info = extract(a.roar, field, grid, r, a.bounds)
            for n in a.budgets:
                row = {"field": name, "method": "marching tetrahedra %d³ + QEM" % r, "budget": n,
                       "values": info["values"], "gradients": info["gradients"]}
                mesh = os.path.join(a.out, "%s-mt-%d-%d.obj" % (name, r, n))
                if info["faces"] < n:
                    row["error"] = "the grid gives %d faces, under the budget" % info["faces"]
                else:
                    proc, seconds, peak = timed([a.roar, "decimate", grid, "-o", mesh, "--faces", str(n)])
                    row["seconds"] = info["seconds"] + seconds
                    row["peak_bytes"] = max(info["peak_bytes"] or 0, peak or 0)
                    if proc.returncode != 0:
                        row["error"] = proc.stderr.strip().splitlines()[-1]
                    else:
                        row.update(evaluate(a.roar, mesh, ref, a.samples))
                print(row, file=sys.stderr)
                rows.append(row)
            if a.meshlab:
                rows += meshlab_rows(a, name, r, grid, info, ref)
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(rows, f, indent=1)
    lines = ["| field | method | N | SDF values | SDF gradients | seconds | peak GB | closed | genus "
             "| self-int. faces | Chamfer/diag (floor-free) | normal cosine | sampled Chamfer/diag |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            lines.append("| %s | %s | %d | %s | %s | | | | | | %s | | |" % (
                r["field"], r["method"], r["budget"], r.get("values", ""), r.get("gradients", ""), r["error"]))
            continue
        peak = "n/a" if r["peak_bytes"] is None else "%.2f" % (r["peak_bytes"] / 1e9)
        lines.append("| %s | %s | %d | %d | %d | %.0f | %s | %s | %s | %s | %.3e | %.4f | %.3e |" % (
            r["field"], r["method"], r["budget"], r["values"], r["gradients"], r["seconds"],
            peak, "yes" if r["closed"] else "no", r["genus"], r["self_intersecting_faces"],
            r["chamfer_exact_over_diag"], r["normal_cosine_exact"], r["chamfer_over_diag"]))
    table = "\n".join(lines) + "\n"
    with open(os.path.join(a.out, "table.md"), "w") as f:
        f.write(table)
    print(table)


if __name__ == "__main__":
    main()
