#!/usr/bin/env python3
"""Writes a large generated soup for the size run: a torus of N x M quads as binary STL
(2 N M triangles, every triangle with its own three corners, as STL stores them), rippled so
that it is not a smooth surface. Usage: size_run.py OUT.stl [FACES] (default 5 000 000)."""
import math
import struct
import sys


def main():
    out = sys.argv[1]
    faces = int(sys.argv[2]) if len(sys.argv) > 2 else 5_000_000
    m = max(3, int(math.sqrt(faces / 2 / 2.5)))
    n = max(3, faces // (2 * m))
    grid = []
    for i in range(n):
        u = 2 * math.pi * i / n
        row = []
        for j in range(m):
            v = 2 * math.pi * j / m
            r = 0.35 + 0.02 * math.sin(17 * u) * math.cos(11 * v)
            big = 1.0 + r * math.cos(v)
            row.append((big * math.cos(u), big * math.sin(u), r * math.sin(v)))
        grid.append(row)
    tri = struct.Struct("<12fH")
    with open(out, "wb") as f:
        f.write(b"roar size run".ljust(80, b" "))
        f.write(struct.pack("<I", 2 * n * m))
        for i in range(n):
            a_row, b_row = grid[i], grid[(i + 1) % n]
            for j in range(m):
                k = (j + 1) % m
                a, b, c, d = a_row[j], b_row[j], b_row[k], a_row[k]
                f.write(tri.pack(0, 0, 0, *a, *b, *c, 0))
                f.write(tri.pack(0, 0, 0, *a, *c, *d, 0))
    print(f"wrote {out}: {2 * n * m} triangles")


if __name__ == "__main__":
    main()
