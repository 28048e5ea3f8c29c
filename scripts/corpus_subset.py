#!/usr/bin/env python3
"""A stratified subset of the corpus manifest, by family and by input size, for
scripts/evaluate_corpus.sh --subset.

    scripts/corpus_subset.py [--manifest PATH] [-n 50] [--min-per-family 5] [-o FILE]

Each family first gets min(its size, --min-per-family) models, so the small families (cad,
organic) are not left with one or two; the rest of the n is shared out in proportion to the
families' sizes (largest remainder, ties to the larger family, then by name). Inside a family
the models are sorted by input face count (then id) and cut into as many runs of equal length
as the family's share; the model in the middle of each run is taken, so the picks spread evenly
over the family's input sizes, from its smallest models to its largest. No randomness: the same
manifest gives the same subset.

Writes a TSV of `id`, `family`, `input_faces` (the first column is what the evaluation reads;
the others are there to be read), after comment lines naming the manifest it came from and its
SHA-256. Standard library only.
"""

import argparse
import csv
import hashlib
import os
import sys


def read_manifest(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    for column in ("id", "family", "input_faces"):
        if rows and column not in rows[0]:
            sys.exit("%s has no column %r" % (path, column))
    return rows


def allocate(sizes, n, floor):
    """Models per family: min(size, floor) each, the rest in proportion to size."""
    if n >= sum(sizes.values()):
        return dict(sizes)
    share = {f: min(s, floor) for f, s in sizes.items()}
    left = n - sum(share.values())
    if left < 0:
        sys.exit("-n %d is below %d families × --min-per-family %d" % (n, len(sizes), floor))
    room = {f: sizes[f] - share[f] for f in sizes}
    total = sum(room.values())
    exact = {f: left * room[f] / total for f in sizes}
    for f in sizes:
        share[f] += int(exact[f])
    remaining = n - sum(share.values())
    order = sorted(sizes, key=lambda f: (-(exact[f] - int(exact[f])), -sizes[f], f))
    for f in order[:remaining]:
        share[f] += 1
    return share


def pick(rows, k):
    """k rows spread evenly over the rows sorted by input size: the middle of each of k runs."""
    rows = sorted(rows, key=lambda r: (int(r["input_faces"]), r["id"]))
    n = len(rows)
    return [rows[(2 * i + 1) * n // (2 * k)] for i in range(k)]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    default_data = os.environ.get("ROAR_TEST_DATA") or os.path.join(here, "..", "..", "shared",
                                                                    "data", "meshes")
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manifest", default=os.path.join(default_data, "..", "corpus",
                                                           "manifest.tsv"))
    parser.add_argument("-n", type=int, default=50, help="models in the subset")
    parser.add_argument("--min-per-family", type=int, default=5)
    parser.add_argument("-o", "--output", default=os.path.join(here, "corpus-subset-50.tsv"))
    args = parser.parse_args()

    rows = read_manifest(args.manifest)
    families = {}
    for row in rows:
        families.setdefault(row["family"], []).append(row)
    share = allocate({f: len(r) for f, r in families.items()}, args.n, args.min_per_family)
    chosen = []
    for family in sorted(families):
        chosen += pick(families[family], share[family])
    with open(args.manifest, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    lines = [
        "# %d of the %d models of the corpus manifest (sha256 %s), by scripts/corpus_subset.py "
        "-n %d --min-per-family %d" % (len(chosen), len(rows), digest, args.n,
                                       args.min_per_family),
        "# per family: " + ", ".join("%s %d of %d" % (f, share[f], len(families[f]))
                                     for f in sorted(families)),
        "id\tfamily\tinput_faces",
    ]
    lines += ["%s\t%s\t%s" % (r["id"], r["family"], r["input_faces"]) for r in chosen]
    tmp = args.output + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, args.output)
    print("wrote %s: %s" % (args.output, lines[1][2:]), file=sys.stderr)


if __name__ == "__main__":
    main()
