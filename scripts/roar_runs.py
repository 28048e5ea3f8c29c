"""Helpers the evaluation scripts share: run a command under /usr/bin/time, and read the figures
of a table from `roar eval --json`. Plain python3, no packages."""

import json
import subprocess
import tempfile
import time


def timed(cmd, **kwargs):
    """Runs `cmd` under /usr/bin/time -v; returns (completed process, seconds, peak bytes). The
    process's stderr is the command's own (time writes to a file of its own)."""
    with tempfile.NamedTemporaryFile(mode="r", suffix=".time") as report:
        started = time.perf_counter()
        proc = subprocess.run(["/usr/bin/time", "-v", "-o", report.name] + cmd, capture_output=True,
                              text=True, **kwargs)
        seconds = time.perf_counter() - started
        peak = None
        for line in report.read().splitlines():
            if "Maximum resident set size" in line:
                peak = int(line.split(":")[1]) * 1024
    return proc, seconds, peak


def evaluate(roar, mesh, ref, samples=None):
    """The figures of the table from `roar eval MESH --ref REF --json [--samples SAMPLES]`."""
    cmd = [roar, "eval", mesh, "--ref", ref, "--json"]
    if samples:
        cmd += ["--samples", str(samples)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        return {"error": proc.stderr.strip()}
    r = json.loads(proc.stdout)
    topo = r["topology_welded"]
    return {
        "faces": topo["faces"],
        "closed": bool(topo["watertight"]),
        "genus": topo.get("genus"),
        "components": topo["components"],
        "self_intersecting_faces": (r.get("self_intersections") or {}).get("faces"),
        "signed_volume": (r.get("orientation") or {}).get("signed_volume"),
        "chamfer_over_diag": r["fidelity"]["chamfer_l2_over_diag"],
        "normal_cosine": r["fidelity"]["normal_cosine"],
        "chamfer_exact_over_diag": r["fidelity"]["chamfer_exact_over_diag"],
        "normal_cosine_exact": r["fidelity"]["normal_cosine_exact"],
    }
