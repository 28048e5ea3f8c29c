#!/usr/bin/env python3
"""Writes an IDR/VolSDF/NeuS-style implicit network with the geometric initialization of
Atzmon & Lipman (SAL), which makes the network close to |x| - r, as a PyTorch-like state dict
in .safetensors, with the architecture sidecar roar reads (same stem, .json).

Written with numpy and the `safetensors` package only, independently of roar's reader, so the
reader is checked against the layout the Python side produces. The layers are weight-normed as
`torch.nn.utils.weight_norm` stores them (`linL.weight_g` of shape out x 1, `linL.weight_v`),
with each row of v scaled by a random positive factor, as training leaves it, so the reader must
apply w = g v / |v| to get the initialized network back.

At finite width the geometric initialization is a blob around the sphere |x| = r, not the
sphere itself (its zero set's radius spreads by some 10 % at width 64). So beside the network
the script writes STEM.reference.json: points with the network's values there, and points on
its zero set (bisection along rays), both computed here in float64 from the initialized
weights, for tests to compare roar's reader and reconstructions against.

    python3 scripts/make_implicit_fixture.py OUT.safetensors [--radius 0.5] [--hidden 64]
        [--layers 4] [--skip 2] [--multires 4] [--features 8] [--seed 0]
"""
import argparse
import json
import pathlib

import numpy as np
from safetensors.numpy import save_file


def geometric_init(rng, radius, hidden, layers, skip, multires, features):
    """The layers (weight out x in, bias) of the IDR ImplicitNetwork's geometric init."""
    input_ch = 3 + 3 * 2 * multires
    dims = [input_ch] + [hidden] * layers + [1 + features]
    linears = []
    for l in range(len(dims) - 1):
        out_dim = dims[l + 1] - input_ch if l + 1 in skip else dims[l + 1]
        in_dim = dims[l]
        if l == len(dims) - 2:
            w = rng.normal(np.sqrt(np.pi) / np.sqrt(dims[l]), 1e-4, (out_dim, in_dim))
            b = np.full(out_dim, -radius)
        elif multires > 0 and l == 0:
            w = np.zeros((out_dim, in_dim))
            w[:, :3] = rng.normal(0.0, np.sqrt(2) / np.sqrt(out_dim), (out_dim, 3))
            b = np.zeros(out_dim)
        elif multires > 0 and l in skip:
            w = rng.normal(0.0, np.sqrt(2) / np.sqrt(out_dim), (out_dim, in_dim))
            w[:, -(input_ch - 3):] = 0.0
            b = np.zeros(out_dim)
        else:
            w = rng.normal(0.0, np.sqrt(2) / np.sqrt(out_dim), (out_dim, in_dim))
            b = np.zeros(out_dim)
        linears.append((w, b))
    return linears


def forward(linears, x, multires, skip, beta=100.0):
    """The IDR ImplicitNetwork's first output at the rows of x (float64)."""
    encoded = np.concatenate(
        [x] + [f(2.0**k * x) for k in range(multires) for f in (np.sin, np.cos)], axis=1)
    h = encoded
    for l, (w, b) in enumerate(linears):
        if l in skip:
            h = np.concatenate([h, encoded], axis=1) / np.sqrt(2)
        h = h @ w.T + b
        if l < len(linears) - 1:
            h = np.logaddexp(0.0, beta * h) / beta
    return h[:, 0]


def zero_set(linears, multires, skip, rays, rng):
    """Points where the network crosses zero along random rays from the origin (inside there)."""
    d = rng.normal(size=(rays, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    lo, hi = np.zeros(rays), np.full(rays, 1.0)
    assert (forward(linears, 0.0 * d, multires, skip) < 0).all(), "the origin must be inside"
    assert (forward(linears, d, multires, skip) > 0).all(), "|x| = 1 must be outside"
    for _ in range(60):
        mid = (lo + hi) / 2
        inside = forward(linears, d * mid[:, None], multires, skip) < 0
        lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
    return d * ((lo + hi) / 2)[:, None]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=pathlib.Path)
    parser.add_argument("--radius", type=float, default=0.5)
    parser.add_argument("--hidden", type=int, default=64)
    parser.add_argument("--layers", type=int, default=4)
    parser.add_argument("--skip", type=int, nargs="*", default=[2])
    parser.add_argument("--multires", type=int, default=4)
    parser.add_argument("--features", type=int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    rng = np.random.default_rng(args.seed)
    linears = geometric_init(rng, args.radius, args.hidden, args.layers, args.skip,
                             args.multires, args.features)
    tensors = {}
    for l, (w, b) in enumerate(linears):
        g = np.linalg.norm(w, axis=1, keepdims=True)
        v = w * rng.uniform(0.5, 2.0, (w.shape[0], 1))
        key = f"implicit_network.lin{l}"
        tensors[f"{key}.weight_g"] = g.astype(np.float32)
        tensors[f"{key}.weight_v"] = v.astype(np.float32)
        tensors[f"{key}.bias"] = b.astype(np.float32)
    save_file(tensors, str(args.out))
    sidecar = {
        "d_in": 3,
        "d_hidden": args.hidden,
        "n_layers": args.layers,
        "skip_in": args.skip,
        "multires": args.multires,
        "softplus_beta": 100.0,
        "output_index": 0,
        "scale": 1.0,
    }
    args.out.with_suffix(".json").write_text(json.dumps(sidecar, indent=2) + "\n")

    points = rng.uniform(-1.0, 1.0, (200, 3))
    surface = zero_set(linears, args.multires, args.skip, 400, rng)
    radii = np.linalg.norm(surface, axis=1)
    reference = {
        "points": points.tolist(),
        "values": forward(linears, points, args.multires, args.skip).tolist(),
        "zero_set": surface.tolist(),
        "zero_set_radius": {"mean": radii.mean(), "min": radii.min(), "max": radii.max()},
    }
    args.out.with_suffix(".reference.json").write_text(json.dumps(reference) + "\n")


if __name__ == "__main__":
    main()
