#!/usr/bin/env python3
"""Writes the exact signed distance of a closed mesh on a regular grid, as the `.npy` volume and
`.json` bounds sidecar `roar reconstruct` reads (docs/sdf.md, "Dense grids"): negative inside,
float32, over the cube around the mesh's bounding box enlarged by `--padding` of its longest side
on every side. The distances come from point_cloud_utils (closest point on the triangles, the
sign from the winding of the closed mesh), independently of roar.

    scripts/mesh_sdf_grid.py MESH OUT.npy [--resolution 256] [--padding 0.1]

Run it with the evaluation virtualenv (scripts/eval_venv.sh prints its python).
"""
import argparse
import json
import pathlib

import numpy as np
import point_cloud_utils as pcu


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("mesh")
    p.add_argument("out", type=pathlib.Path)
    p.add_argument("--resolution", type=int, default=256, help="samples along each axis")
    p.add_argument("--padding", type=float, default=0.1)
    a = p.parse_args()
    if a.out.suffix != ".npy":
        raise SystemExit("mesh_sdf_grid: OUT must end in .npy")
    v, f = pcu.load_mesh_vf(a.mesh)
    v = v.astype(np.float64)
    low, high = v.min(axis=0), v.max(axis=0)
    half = 0.5 * (high - low).max() * (1.0 + 2.0 * a.padding)
    center = 0.5 * (low + high)
    lo, hi = center - half, center + half
    n = a.resolution
    axes = [np.linspace(lo[i], hi[i], n) for i in range(3)]
    volume = np.empty((n, n, n), dtype=np.float32)
    grid_yz = np.stack(np.meshgrid(axes[1], axes[2], indexing="ij"), axis=-1).reshape(-1, 2)
    for i, x in enumerate(axes[0]):
        points = np.column_stack([np.full(len(grid_yz), x), grid_yz])
        distances, _, _ = pcu.signed_distance_to_mesh(points, v, f)
        volume[i] = distances.reshape(n, n)
    np.save(a.out, volume)
    a.out.with_suffix(".json").write_text(json.dumps({"min": lo.tolist(), "max": hi.tolist()}))
    print(f"{a.out}: {n}³ samples over {lo.tolist()} .. {hi.tolist()}")


if __name__ == "__main__":
    main()
