#!/usr/bin/env python3
"""Two sets of roar outputs side by side: per mesh and budget, Chamfer/diag and abs normal cosine
of each (from `roar eval OUT --ref IN --json`), the change, whether each output is closed,
exactly N faces and free of self-intersections, then the median and worst change per budget.

    scripts/compare_runs.py BEFORE_DIR AFTER_DIR [--meshes FILE] [--budgets "1000 5000"]

Each DIR holds `<mesh>-<N>.json` (the eval report) and `<mesh>-<N>.rep.json` (roar's report,
for the init genus and the handles removed; optional). `--meshes FILE`: names (with their
extension) to take, one or more per line; default every mesh found in BEFORE_DIR.
"""
import argparse
import json
import os
import statistics


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def row(ev, n):
    fid, top = ev["fidelity"], ev["topology"]
    si = (ev.get("self_intersections") or {}).get("faces")
    ok = top["faces"] == n and top["watertight"] and si == 0
    return fid["chamfer_l2_over_diag"], fid["normal_cosine_abs"], ok, top["genus"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--meshes")
    ap.add_argument("--budgets", default="1000 5000")
    args = ap.parse_args()
    if args.meshes:
        names = open(args.meshes).read().split()
        stems = [os.path.splitext(m)[0] for m in names]
    else:
        stems = sorted({f.rsplit("-", 1)[0] for f in os.listdir(args.before)
                        if f.endswith(".json") and not f.endswith(".rep.json")})
    for n in map(int, args.budgets.split()):
        lines, dc, dn, missing = [], [], [], []
        for stem in stems:
            b = load(os.path.join(args.before, f"{stem}-{n}.json"))
            a = load(os.path.join(args.after, f"{stem}-{n}.json"))
            if b is None or a is None:
                missing.append(stem)
                continue
            cb, nb, okb, gb = row(b, n)
            ca, na, oka, ga = row(a, n)
            rep = load(os.path.join(args.after, f"{stem}-{n}.rep.json")) or {}
            removed = len(rep.get("run", {}).get("finish", {}).get("handles_removed", []))
            dc.append(ca / cb - 1)
            dn.append(na - nb)
            lines.append(f"| {stem} | {cb:.3e} → {ca:.3e} | {100 * dc[-1]:+.1f} % | "
                         f"{nb:.4f} → {na:.4f} | {dn[-1]:+.4f} | {gb} → {ga} | {removed} | "
                         f"{'yes' if okb else 'NO'} / {'yes' if oka else 'NO'} |")
        print(f"\n### {n} faces\n")
        print("| mesh | Chamfer/diag before → after | change | abs normal cosine before → after "
              "| change | genus | handles removed | closed, exact, no SI (before / after) |")
        print("|---|---|---|---|---|---|---|---|")
        print("\n".join(lines))
        if dc:
            print(f"\n{len(dc)} meshes: median Chamfer/diag change {100 * statistics.median(dc):+.2f} %, "
                  f"worst {100 * max(dc):+.2f} %; median normal cosine change "
                  f"{statistics.median(dn):+.4f}, worst {min(dn):+.4f}.")
        if missing:
            print(f"Not in both: {' '.join(missing)}")


if __name__ == "__main__":
    main()
