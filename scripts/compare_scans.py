#!/usr/bin/env python3
"""The work of scripts/compare_scans.sh (read its header): runs roar and the peers on one scan
set, evaluates every output against the reference and writes OUT/table.md and OUT/results.json."""

import argparse
import json
import os
import subprocess
import sys

from roar_runs import evaluate, timed


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--roar", required=True)
    p.add_argument("--set", required=True)
    p.add_argument("--ref", required=True)
    p.add_argument("--budgets", type=int, nargs="+", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--peers", required=True)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    rows = []

    patches = os.path.join(a.out, "patches.ply")
    proc, seconds, peak = timed([a.roar, "scans", a.set, "-o", patches, "-q"])
    if proc.returncode != 0:
        sys.exit("compare_scans: roar scans failed: " + proc.stderr.strip().splitlines()[-1])
    print("patches: %.1f s" % seconds, file=sys.stderr)

    for n in a.budgets:
        mesh = os.path.join(a.out, "roar-%d.obj" % n)
        print("roar at %d faces" % n, file=sys.stderr)
        proc, seconds, peak = timed([a.roar, "reconstruct", a.set, "-o", mesh, "--faces", str(n), "-q"])
        row = {"method": "roar", "budget": n, "seconds": seconds, "peak_bytes": peak}
        if proc.returncode != 0:
            row["error"] = proc.stderr.strip().splitlines()[-1]
        else:
            row.update(evaluate(a.roar, mesh, a.ref))
        rows.append(row)

    budgets = [str(n) for n in a.budgets]
    for method, source in [("poisson", patches), ("alphawrap", patches), ("qem", a.ref)]:
        print("%s on %s" % (method, os.path.basename(source)), file=sys.stderr)
        outdir = os.path.join(a.out, method)
        proc = subprocess.run([sys.executable, a.peers, method, source, outdir, "--budgets"] + budgets,
                              capture_output=True, text=True)
        if proc.returncode != 0:
            for n in a.budgets:
                rows.append({"method": method, "budget": n, "error": proc.stderr.strip()[-300:]})
            continue
        result = json.loads(proc.stdout)
        for n in a.budgets:
            entry = result["budgets"][str(n)]
            row = {"method": method + ("" if method == "qem" else "+qem"), "budget": n,
                   "seconds": entry.get("seconds"), "peak_bytes": result.get("peak_bytes")}
            if "error" in entry:
                row["error"] = entry["error"]
            else:
                row.update(evaluate(a.roar, entry["output"], a.ref))
            rows.append(row)

    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(rows, f, indent=1)
    lines = ["| method | N | faces | closed | self-int. faces | genus | components | volume > 0 "
             "| Chamfer/diag | normal cosine | seconds | peak GB |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in sorted(rows, key=lambda r: (r["budget"], r["method"])):
        if "error" in r:
            lines.append("| %s | %d | error: %s |" % (r["method"], r["budget"], r["error"]))
            continue
        vol = r.get("signed_volume")
        lines.append("| %s | %d | %d | %s | %s | %s | %d | %s | %.3e | %.4f | %s | %s |" % (
            r["method"], r["budget"], r["faces"], "yes" if r["closed"] else "no",
            r["self_intersecting_faces"], r["genus"], r["components"],
            "n/a" if vol is None else ("yes" if vol > 0 else "no"),
            r["chamfer_over_diag"], r["normal_cosine"],
            "n/a" if r["seconds"] is None else "%.0f" % r["seconds"],
            "n/a" if r["peak_bytes"] is None else "%.2f" % (r["peak_bytes"] / 1e9)))
    table = "\n".join(lines) + "\n"
    with open(os.path.join(a.out, "table.md"), "w") as f:
        f.write(table)
    print(table)


if __name__ == "__main__":
    main()
