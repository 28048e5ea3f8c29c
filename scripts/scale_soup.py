#!/usr/bin/env python3
"""Writes a large soup made of corpus models for the scale run: at least --models different models
of the corpus manifest (seeded, every family represented), each scaled to a random size and
placed with a random rotation and offset inside one box, so that the parts overlap and
interpenetrate as in a cluttered scene; copies with new transforms are added until the soup has
exactly FACES triangles (the last copy is cut short, leaving it open). Only models with at most
FACES / K faces are picked, so that each of the K appears at least once. Written as binary STL,
every triangle with its own three corners, as STL stores them.

Usage: scale_soup.py OUT.stl [FACES] [--manifest PATH] [--models K] [--seed S]
(default FACES 5 000 000, manifest $ROAR_TEST_DATA/../corpus/manifest.tsv, 50 models, seed 0).
Needs numpy (the evaluation virtualenv has it: scripts/eval_venv.sh).
"""
import argparse
import csv
import math
import os
import random
import struct
import sys

import numpy as np

from punctured import read_mesh  # this folder's OBJ, OFF and STL reader


def default_manifest():
    data = os.environ.get("ROAR_TEST_DATA") or os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data", "meshes")
    return os.path.normpath(os.path.join(data, "..", "corpus", "manifest.tsv"))


def pick_models(manifest, count, most_faces, rng):
    """`count` rows of the manifest with at most `most_faces` faces each (its `input_faces`
    column), round-robin over its families in a seeded order."""
    with open(manifest, newline="") as f:
        rows = [row for row in csv.DictReader(f, delimiter="\t")
                if int(row.get("input_faces") or 0) <= most_faces]
    families = {}
    for row in rows:
        families.setdefault(row.get("family", ""), []).append(row)
    for group in families.values():
        rng.shuffle(group)
    order = sorted(families)
    picked = []
    while len(picked) < min(count, len(rows)):
        for family in order:
            if families[family] and len(picked) < count:
                picked.append(families[family].pop())
    base = os.path.dirname(os.path.abspath(manifest))
    return [(row["id"], os.path.join(base, row["path"])) for row in picked]


def load_triangles(path):
    """The model's triangles as a (F, 3, 3) float array, centred and scaled to unit size."""
    verts, faces = read_mesh(path)
    if not faces:
        return None
    corners = np.asarray(verts, dtype=np.float64)[np.asarray(faces)]
    low, high = corners.reshape(-1, 3).min(0), corners.reshape(-1, 3).max(0)
    size = float((high - low).max())
    if not math.isfinite(size) or size <= 0:
        return None
    return (corners - 0.5 * (low + high)) / size


def random_rotation(rng):
    """A uniformly random rotation matrix (from a random unit quaternion)."""
    q = np.array([rng.gauss(0, 1) for _ in range(4)])
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("faces", nargs="?", type=int, default=5_000_000)
    parser.add_argument("--manifest", default=default_manifest())
    parser.add_argument("--models", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    if args.faces < 1 or args.models < 1:
        sys.exit("faces and models must be positive")
    rng = random.Random(args.seed)
    models = []
    # Every model fits the soup at least once: none has more than its share of the faces.
    for model_id, path in pick_models(args.manifest, args.models, args.faces // args.models, rng):
        corners = load_triangles(path)
        if corners is not None:
            models.append((model_id, corners))
    if not models:
        sys.exit("no model of %s could be read" % args.manifest)
    # The box the parts are placed in grows with the number of copies, so that about 8 parts
    # overlap any point whatever the size of the soup.
    copies_expected = max(1, args.faces / (sum(len(c) for _, c in models) / len(models)))
    box = max(1.0, (copies_expected / 8.0) ** (1.0 / 3.0))
    written = copies = 0
    with open(args.out, "wb") as f:
        f.write(b"roar scale run: corpus models".ljust(80, b" "))
        f.write(struct.pack("<I", args.faces))
        while written < args.faces:
            _, corners = models[copies % len(models)]
            scale = rng.uniform(0.3, 1.0)
            offset = np.array([rng.uniform(0, box) for _ in range(3)])
            placed = corners[: args.faces - written] @ (scale * random_rotation(rng)).T + offset
            # One STL record per triangle: a zero normal, three corners, a zero attribute.
            block = np.zeros(len(placed), dtype=[("t", "<f4", 12), ("a", "<u2")])
            block["t"][:, 3:] = placed.reshape(-1, 9)
            f.write(block.tobytes())
            written += len(placed)
            copies += 1
    print("wrote %s: %d triangles, %d copies of %d models" % (
        args.out, written, copies, len(models)))


if __name__ == "__main__":
    main()
