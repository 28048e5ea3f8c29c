#!/usr/bin/env python3
"""Peer reconstructions for scripts/evaluate.sh: one input mesh, one peer, every budget.

    peers.py METHOD INPUT OUTDIR --budgets 1000 5000

METHOD is `alphawrap` (CGAL 3D Alpha Wrapping through PyMeshLab, alpha = diag/300,
offset = diag/1000), `manifold` (Huang et al. 2018 through point-cloud-utils'
`make_mesh_watertight`, resolution 20000), `poisson` (Screened Poisson through PyMeshLab,
depth 8, on the input's vertices with area-weighted normals of its oriented faces, for
range-scan patches) or `qem` (no reconstruction: the input itself, decimated). The peer runs once; its surface is then
decimated to each budget with MeshLab's topology-preserving quadric edge collapse
(`preservetopology`, `preservenormal`, `planarquadric`), and written as
`OUTDIR/<budget>.obj`.

Prints one JSON object on stdout: the peer's own seconds, its raw face count, the
parameter names it used, and per budget the QEM seconds, face count and output path
(or an `error`). Runs in its own process so that a crash of a peer library cannot take
the whole evaluation down.
"""

import argparse
import json
import os
import resource
import sys
import time

import numpy as np
import pymeshlab

# Peer settings of the end-to-end issue (documented in docs/evaluation.md).
ALPHA_OVER_DIAG = 1.0 / 300.0
OFFSET_OVER_DIAG = 1.0 / 1000.0
MANIFOLD_RESOLUTION = 20000
POISSON_DEPTH = 8


def load(path):
    """Vertices (float64, n×3) and triangles (int32, m×3) of any mesh file MeshLab reads."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(path)
    m = ms.current_mesh()
    return (
        np.ascontiguousarray(m.vertex_matrix(), dtype=np.float64),
        np.ascontiguousarray(m.face_matrix(), dtype=np.int32),
    )


def bbox_diagonal(v):
    """Length of the axis-aligned bounding box diagonal of the referenced vertices."""
    return float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))


def alpha_wrap(v, f):
    """CGAL alpha wrap through PyMeshLab; returns (vertices, faces, parameter note).

    PyMeshLab renamed the parameters across versions: recent ones take `alpha`/`offset`
    as a `PercentageValue` of the bounding-box diagonal, older ones `alpha_fraction`/
    `offset_fraction` as plain fractions. Try the new names first.
    """
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f))
    names = set(ms.filter_parameter_values("generate_alpha_wrap"))
    if "alpha" in names:
        ms.generate_alpha_wrap(
            alpha=pymeshlab.PercentageValue(100.0 * ALPHA_OVER_DIAG),
            offset=pymeshlab.PercentageValue(100.0 * OFFSET_OVER_DIAG),
        )
        params = "alpha/offset as PercentageValue"
    else:
        ms.generate_alpha_wrap(alpha_fraction=ALPHA_OVER_DIAG, offset_fraction=OFFSET_OVER_DIAG)
        params = "alpha_fraction/offset_fraction"
    m = ms.current_mesh()
    return m.vertex_matrix(), m.face_matrix(), params


def manifold(v, f):
    """Manifold (octree + projection) through point-cloud-utils."""
    import point_cloud_utils as pcu

    vw, fw = pcu.make_mesh_watertight(v, f, resolution=MANIFOLD_RESOLUTION)
    return np.asarray(vw, dtype=np.float64), np.asarray(fw, dtype=np.int32), "resolution=20000"


def poisson(v, f):
    """Screened Poisson (Kazhdan & Hoppe 2013) through PyMeshLab, depth 8, on the vertices with
    the area-weighted normals of the faces around them (patches face their scanner)."""
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f))
    ms.compute_normal_per_vertex(weightmode="By Area")
    ms.generate_surface_reconstruction_screened_poisson(depth=POISSON_DEPTH, preclean=True)
    m = ms.current_mesh()
    return m.vertex_matrix(), m.face_matrix(), "depth=%d" % POISSON_DEPTH


def as_is(v, f):
    """The input unchanged (the `qem` method decimates it alone)."""
    return v, f, "input decimated"


PEERS = {"alphawrap": alpha_wrap, "manifold": manifold, "poisson": poisson, "qem": as_is}


def decimate(v, f, faces):
    """MeshLab QEM to `faces`, topology preserved; returns (vertices, faces, seconds)."""
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f))
    started = time.perf_counter()
    if len(f) > faces:
        ms.meshing_decimation_quadric_edge_collapse(
            targetfacenum=faces,
            preservetopology=True,
            preservenormal=True,
            planarquadric=True,
        )
    ms.meshing_remove_unreferenced_vertices()
    seconds = time.perf_counter() - started
    m = ms.current_mesh()
    return m.vertex_matrix(), m.face_matrix(), seconds


def write_obj(path, v, f):
    """Plain OBJ (positions and 1-based triangles only), written atomically."""
    tmp = path + ".tmp"
    with open(tmp, "w") as out:
        out.write("".join("v %.17g %.17g %.17g\n" % tuple(p) for p in v))
        out.write("".join("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in f))
    os.replace(tmp, path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("method", choices=sorted(PEERS))
    parser.add_argument("input")
    parser.add_argument("outdir")
    parser.add_argument("--budgets", type=int, nargs="+", required=True)
    args = parser.parse_args()
    os.makedirs(args.outdir, exist_ok=True)

    v, f = load(args.input)
    result = {"method": args.method, "input_faces": int(len(f)), "budgets": {}}
    started = time.perf_counter()
    peer = PEERS[args.method]
    pv, pf, params = peer(v, f)
    result["peer_seconds"] = time.perf_counter() - started
    result["peer_faces"] = int(len(pf))
    result["params"] = params
    result["diag"] = bbox_diagonal(v)

    for budget in args.budgets:
        entry = {}
        try:
            dv, df, seconds = decimate(pv, pf, budget)
            path = os.path.join(args.outdir, "%d.obj" % budget)
            write_obj(path, dv, df)
            entry = {
                "output": path,
                "faces": int(len(df)),
                "qem_seconds": seconds,
                "seconds": result["peer_seconds"] + seconds,
            }
            if len(pf) < budget:
                entry["note"] = "peer made only %d faces (< budget); not refined" % len(pf)
        except Exception as e:  # one budget failing must not hide the others
            entry = {"error": "%s: %s" % (type(e).__name__, e)}
        result["budgets"][str(budget)] = entry
    # Peak resident memory of this process (the peer and its QEM), in bytes.
    result["peak_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    json.dump(result, sys.stdout)
    print()


if __name__ == "__main__":
    main()
