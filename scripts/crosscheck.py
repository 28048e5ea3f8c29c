#!/usr/bin/env python3
"""Cross-checks `roar eval --json` against trimesh, MeshLab (pymeshlab) and numpy/scipy.

Usage: crosscheck.py DATA_DIR ROAR_CMD...   (ROAR_CMD is the command that takes
`MESH [--ref REF] [--samples N] [--seed S]` and prints the roar_eval Report as JSON).

For every mesh of DATA_DIR/{clean,wild} it compares, on the mesh welded at bit-identical
positions unless noted:
  F      face count as stored (fan-triangulated polygons)
  Vr     referenced welded vertices
  wt     watertight (every edge of a non-degenerate triangle has two faces)      [trimesh]
  bnd    boundary edges                                          [MeshLab topological measures]
  nmE    non-manifold edges (>2 faces)                        [numpy; MeshLab's non_two_manifold_edges
         counts face-edge incidences on them, checked as nmE_ml = their sum]
  selfX  self-intersecting faces       [MeshLab compute_selection_by_self_intersections_per_face]
  vol    signed volume sum a.(b x c)/6 of the stored mesh     [numpy; trimesh's volume as vol_tm
         when the welded mesh is watertight and consistently wound]
  Q50    median aspect ratio R/(2r) of the stored non-degenerate faces               [numpy]
and the Chamfer distance between bunny and a perturbed copy (scipy cKDTree on trimesh samples).
Exits 1 when any figure disagrees beyond its tolerance (listed in TOLERANCES below).
"""

import json
import os
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np
import pymeshlab
import trimesh
from scipy.spatial import cKDTree

# selfX: |ours - MeshLab| <= max(5, 2 %), except for the files below, where our exact count is
# known to exceed MeshLab's (pairs sharing an edge or a vertex, exact touches that MeshLab's
# floating-point tests decide inconsistently; see crates/roar-eval/tests/real_files.rs): there we
# only require ours >= MeshLab's.
SELFX_EXCEPTIONS = {
    "trimesh-cycloidal.ply", "trimesh-box.STL", "trimesh-featuretype.STL",
    "trimesh-angle_block.STL", "trimesh-not_convex.obj", "manifoldplus-bathtub.obj",
    "manifoldplus-bed.obj", "manifoldplus-chair.off", "manifoldplus-table.off",
    "manifold-input.obj", "c3d-beetle.obj", "luke-cruiser.obj",
}
TOLERANCES = "F, Vr, wt, bnd, nmE, nmE_ml exact; selfX max(5, 2%); vol, vol_tm, Q50 rel 1e-6; Chamfer 3%"
CHAMFER_SAMPLES = 200_000


def load(path):
    """Positions (float64) and fan-triangulated faces as stored in the file."""
    ext = os.path.splitext(path)[1].lower()
    if ext in (".obj", ".off"):
        v, f = [], []
        text = open(path, encoding="utf-8", errors="replace").read()
        if ext == ".obj":
            for line in text.splitlines():
                w = line.split()
                if not w:
                    continue
                if w[0] == "v":
                    v.append([float(x) for x in w[1:4]])
                elif w[0] == "f":
                    idx = [int(t.split("/")[0]) for t in w[1:]]
                    idx = [i - 1 if i > 0 else len(v) + i for i in idx]
                    f += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
        else:
            tok = " ".join(l.split("#")[0] for l in text.splitlines()).split()
            assert tok[0].endswith("OFF"), path
            nv, nf = int(tok[1]), int(tok[2])
            at = 4
            v = np.array(tok[at:at + 3 * nv], dtype=np.float64).reshape(-1, 3).tolist()
            at += 3 * nv
            for _ in range(nf):
                k = int(tok[at])
                idx = [int(x) for x in tok[at + 1:at + 1 + k]]
                at += 1 + k
                f += [[idx[0], idx[j], idx[j + 1]] for j in range(1, k - 1)]
        return np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64).reshape(-1, 3)
    m = trimesh.load(path, process=False, force="mesh")
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)


def weld(v, f):
    """Bit-identical welding (-0.0 == 0.0); returns positions and faces with distinct corners."""
    u, inv = np.unique(v + 0.0, axis=0, return_inverse=True)
    wf = inv.reshape(-1)[f]
    ok = (wf[:, 0] != wf[:, 1]) & (wf[:, 1] != wf[:, 2]) & (wf[:, 0] != wf[:, 2])
    return u, wf[ok]


def aspect_ratio_median(v, f):
    ok = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    a, b, c = (v[f[ok, k]] for k in range(3))
    la = np.linalg.norm(b - c, axis=1)
    lb = np.linalg.norm(c - a, axis=1)
    lc = np.linalg.norm(a - b, axis=1)
    # R/(2r) = abc·s / (8K²), the area K from the cross product (Heron's (s−a)(s−b)(s−c)
    # cancels on flat triangles, which would then drop out of the median).
    twice_area = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    den = 4.0 * twice_area * twice_area
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        q = la * lb * lc * (la + lb + lc) / den
    q = q[(den > 0) & np.isfinite(q)]
    return float(np.median(q)) if len(q) else None


def roar(cmd, mesh, *extra):
    out = subprocess.run(cmd + [mesh, *extra], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def close(a, b, rel, absolute=1e-12):
    if a is None or b is None:
        return a is None and b is None
    return abs(a - b) <= max(rel * max(abs(a), abs(b)), absolute)


def selfx_ok(name, ours, theirs):
    if name in SELFX_EXCEPTIONS:
        return ours >= theirs
    return abs(ours - theirs) <= max(5, 0.02 * theirs)


def check_file(cmd, path):
    name = os.path.basename(path)
    r = roar(cmd, path)
    v, f = load(path)
    u, wf = weld(v, f)
    tw = r["topology_welded"]
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(u, wf.astype(np.int32)))
    topo = ms.get_topological_measures()
    ms.compute_selection_by_self_intersections_per_face()
    selfx = int(ms.current_mesh().face_selection_array().sum())
    tm_welded = trimesh.Trimesh(u, wf, process=False)
    edges = np.sort(wf[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    counts = np.unique(edges, axis=0, return_counts=True)[1] if len(wf) else np.zeros(0, int)
    rows = [
        ("F", r["topology"]["faces"], len(f), r["topology"]["faces"] == len(f)),
        ("Vr", tw["vertices_referenced"], len(np.unique(wf)),
         tw["vertices_referenced"] == len(np.unique(wf))),
        ("wt", tw["watertight"], bool(len(wf) and tm_welded.is_watertight),
         tw["watertight"] == bool(len(wf) and tm_welded.is_watertight)),
        ("bnd", tw["boundary_edges"], topo["boundary_edges"],
         tw["boundary_edges"] == topo["boundary_edges"]),
        ("nmE", tw["nonmanifold_edges"], int((counts > 2).sum()),
         tw["nonmanifold_edges"] == int((counts > 2).sum())),
        ("nmE_ml", int(counts[counts > 2].sum()), topo["non_two_manifold_edges"],
         int(counts[counts > 2].sum()) == topo["non_two_manifold_edges"]),
        ("selfX", r["self_intersections"]["faces"], selfx,
         selfx_ok(name, r["self_intersections"]["faces"], selfx)),
    ]
    ours_vol = r["orientation"]["signed_volume"]
    vol = float(np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6.0)
    rows.append(("vol", ours_vol, vol, close(ours_vol, vol, 1e-6)))
    if tw["watertight"] and tw["inconsistent_edges"] == 0:
        tm_vol = float(trimesh.Trimesh(v, f, process=False).volume)
        rows.append(("vol_tm", ours_vol, tm_vol, close(ours_vol, tm_vol, 1e-6)))
    q = aspect_ratio_median(v, f)
    ours_q = r["quality"]["aspect_ratio_median"]
    rows.append(("Q50", ours_q, q, close(ours_q, q, 1e-6)))
    return name, rows


def chamfer_check(cmd, bunny):
    """Chamfer between bunny and a perturbed, slightly scaled copy: roar vs cKDTree."""
    v, f = load(bunny)
    rng = np.random.default_rng(7)
    centre = v.mean(axis=0)
    diag = np.linalg.norm(v.max(axis=0) - v.min(axis=0))
    moved = centre + 1.02 * (v - centre) + rng.normal(scale=2e-3 * diag, size=v.shape)
    with tempfile.TemporaryDirectory() as tmp:
        other = os.path.join(tmp, "bunny-perturbed.obj")
        with open(other, "w") as out:
            out.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in moved.tolist())
            out.writelines(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n" for t in f)
        r = roar(cmd, other, "--ref", bunny, "--samples", str(CHAMFER_SAMPLES))
    ours = r["fidelity"]["chamfer_l2"]
    a, _ = trimesh.sample.sample_surface(trimesh.Trimesh(moved, f, process=False),
                                         CHAMFER_SAMPLES, seed=1)
    b, _ = trimesh.sample.sample_surface(trimesh.Trimesh(v, f, process=False),
                                         CHAMFER_SAMPLES, seed=2)
    theirs = 0.5 * (cKDTree(b).query(a)[0].mean() + cKDTree(a).query(b)[0].mean())
    return ours, theirs, abs(ours - theirs) <= 0.03 * theirs


def fmt(x):
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, float):
        return f"{x:.6g}"
    return str(x)


def main():
    warnings.simplefilter("ignore")  # trimesh's mass properties warn on open soups
    data, cmd = sys.argv[1], sys.argv[2:]
    files = [os.path.join(data, d, n) for d in ("clean", "wild")
             for n in sorted(os.listdir(os.path.join(data, d)))]
    start = time.time()
    bad = 0
    print(f"tolerances: {TOLERANCES}")
    print(f"{'file':34} {'check':5} {'roar':>14} {'reference':>14}")
    for path in files:
        try:
            name, rows = check_file(cmd, path)
        except Exception as e:  # a crash on one file is a failure, reported, not fatal
            print(f"{os.path.basename(path):34} ERROR {e}")
            bad += 1
            continue
        wrong = [row for row in rows if not row[3]]
        bad += len(wrong)
        summary = "ok" if not wrong else "MISMATCH"
        print(f"{name:34} {summary}: " + "  ".join(
            f"{k}={fmt(a)}" + ("" if ok and k != "selfX" else f"(ref {fmt(b)})")
            for k, a, b, ok in rows))
    ours, theirs, ok = chamfer_check(cmd, os.path.join(data, "clean", "bunny.obj"))
    bad += not ok
    print(f"chamfer bunny vs perturbed bunny ({CHAMFER_SAMPLES} samples): roar {ours:.6g}"
          f" scipy {theirs:.6g} ({100 * (ours - theirs) / theirs:+.2f} %) "
          + ("ok" if ok else "MISMATCH"))
    print(f"{len(files)} files in {time.time() - start:.0f} s; {bad} disagreement(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
