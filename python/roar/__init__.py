"""roar: closed, oriented 2-manifold triangle meshes at an exact face budget.

Arrays in and out are numpy: vertices ``(n, 3)`` float32 or float64, faces ``(m, 3)`` int32,
int64 or uint32. Results are float64 vertices and int64 faces. Configuration dicts use the CLI's
TOML layout (``roar reconstruct --print-config``; see :func:`default_config`). While roar works
the GIL is released, so other Python threads run; Ctrl-C raises ``KeyboardInterrupt`` at the next
progress report (once per iteration of the optimization, and between stages).

Errors: ``ValueError`` for unusable arrays or config (raised before any work), ``RoarError`` for
a failure of the work itself, with the CLI's one-line message.
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, Optional, Tuple

import numpy as np

from . import _roar
from ._roar import RoarError

__all__ = [
    "RoarError",
    "reconstruct",
    "reconstruct_file",
    "read_mesh",
    "eval",
    "decimate",
    "init",
    "default_config",
]

_FLOAT_DTYPES = (np.dtype(np.float32), np.dtype(np.float64))
_INDEX_DTYPES = (np.dtype(np.int32), np.dtype(np.int64), np.dtype(np.uint32))


def _vertices_bytes(vertices: Any, name: str = "vertices") -> Tuple[bytes, int]:
    v = np.asarray(vertices)
    if v.dtype not in _FLOAT_DTYPES:
        raise ValueError(f"{name} must be float32 or float64, not {v.dtype}")
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), not {v.shape}")
    if not np.all(np.isfinite(v)):
        row = int(np.argwhere(~np.isfinite(v))[0][0])
        raise ValueError(f"{name}: vertex {row} has a NaN or infinite coordinate")
    return np.ascontiguousarray(v, dtype="<f8").tobytes(), v.shape[0]


def _faces_bytes(faces: Any, n_vertices: int, name: str = "faces") -> bytes:
    f = np.asarray(faces)
    if f.dtype not in _INDEX_DTYPES:
        raise ValueError(f"{name} must be int32, int64 or uint32, not {f.dtype}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"{name} must have shape (m, 3), not {f.shape}")
    if f.shape[0] == 0:
        raise ValueError(f"{name}: the mesh has no triangles")
    low, high = int(f.min()), int(f.max())
    if low < 0 or high >= n_vertices:
        bad = low if low < 0 else high
        raise ValueError(
            f"{name}: index {bad} out of range (the mesh has {n_vertices} vertices)"
        )
    return np.ascontiguousarray(f, dtype="<u4").tobytes()


def _mesh_bytes(vertices: Any, faces: Any) -> Tuple[bytes, bytes]:
    v, n = _vertices_bytes(vertices)
    return v, _faces_bytes(faces, n)


def _arrays(positions: bytes, triangles: bytes) -> Tuple[np.ndarray, np.ndarray]:
    v = np.frombuffer(positions, dtype="<f8").reshape(-1, 3).astype(np.float64)
    f = np.frombuffer(triangles, dtype="<u4").reshape(-1, 3).astype(np.int64)
    return v, f


def _budget(target_faces: Any) -> int:
    if isinstance(target_faces, bool) or not isinstance(target_faces, (int, np.integer)):
        raise ValueError(f"target_faces must be an integer, not {target_faces!r}")
    if target_faces <= 0:
        raise ValueError(f"target_faces must be positive, not {target_faces}")
    return int(target_faces)


def _config_json(config: Optional[Dict[str, Any]]) -> str:
    if config is None:
        return "{}"
    if not isinstance(config, dict):
        raise ValueError(f"config must be a dict, not {type(config).__name__}")
    try:
        return json.dumps(config, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise ValueError(f"config: {e}") from None


def reconstruct(
    vertices: Any,
    faces: Any,
    target_faces: int,
    config: Optional[Dict[str, Any]] = None,
    progress: Optional[Callable[[Dict[str, Any]], None]] = None,
) -> Tuple[np.ndarray, np.ndarray, Dict[str, Any]]:
    """Reconstructs any triangle soup as a closed, oriented 2-manifold with exactly
    ``target_faces`` faces and no self-intersections.

    ``config`` overrides configuration keys (the CLI's TOML layout, e.g.
    ``{"optimize": {"iterations": 100}, "seed": 7}``). ``progress``, if given, is called with a dict
    ``{"stage", "iteration", "iterations", "loss", "faces"}`` at every report the CLI's progress
    bar shows; an exception it raises stops the run and propagates.

    Returns ``(vertices, faces, report)``: float64 ``(n, 3)``, int64 ``(target_faces, 3)`` and
    the CLI's JSON report as a dict (metrics of input and output, stage timings, config, seed).
    """
    v, f = _mesh_bytes(vertices, faces)
    faces_wanted = _budget(target_faces)
    return _reconstruct(v, f, faces_wanted, config, progress, "<arrays>")


def _reconstruct(v, f, faces_wanted, config, progress, label):
    if progress is not None and not callable(progress):
        raise ValueError("progress must be callable")
    p, t, report = _roar.reconstruct(
        v, f, faces_wanted, _config_json(config), label, progress
    )
    out_v, out_f = _arrays(p, t)
    return out_v, out_f, json.loads(report)


def read_mesh(path: "os.PathLike[str] | str") -> Tuple[np.ndarray, np.ndarray]:
    """Reads a mesh file of any format the CLI reads (OBJ, PLY, STL, OFF, glTF ``.gltf``/``.glb``)
    as ``(vertices, faces)``, vertices numbered as in the file, nothing welded."""
    return _arrays(*_roar.read_mesh(os.fspath(path)))


def reconstruct_file(
    path: "os.PathLike[str] | str",
    target_faces: int,
    config: Optional[Dict[str, Any]] = None,
    progress: Optional[Callable[[Dict[str, Any]], None]] = None,
    output: "os.PathLike[str] | str | None" = None,
) -> Tuple[np.ndarray, np.ndarray, Dict[str, Any]]:
    """:func:`reconstruct` on a mesh file of any format the CLI reads; errors name the file.
    With ``output``, the result is also written there (format by extension, atomically)."""
    faces_wanted = _budget(target_faces)
    p, t = _roar.read_mesh(os.fspath(path))
    result = _reconstruct(p, t, faces_wanted, config, progress, os.fspath(path))
    if output is not None:
        _roar.write_mesh(os.fspath(output), *_mesh_bytes(result[0], result[1]))
    return result


def eval(
    vertices: Any,
    faces: Any,
    reference: Optional[Tuple[Any, Any]] = None,
) -> Dict[str, Any]:
    """The metrics report of a mesh (the CLI's ``roar eval --json``): triangle quality,
    self-intersections, non-manifold edges and vertices, boundary, components, genus; with
    ``reference=(vertices, faces)`` also Chamfer distance and normal cosine against it."""
    v, f = _mesh_bytes(vertices, faces)
    ref = None
    if reference is not None:
        rv, n = _vertices_bytes(reference[0], "reference vertices")
        ref = (rv, _faces_bytes(reference[1], n, "reference faces"))
    return json.loads(_roar.eval(v, f, ref))


def decimate(
    vertices: Any,
    faces: Any,
    target_faces: int,
    best_effort: bool = False,
) -> Tuple[np.ndarray, np.ndarray]:
    """The guaranteed QEM (the CLI's ``roar decimate``): a closed, oriented 2-manifold (welded at
    bit-identical positions first) to exactly ``target_faces`` faces, keeping its genus and
    components and adding no self-intersection. Raises ``RoarError`` when the vetoes block the
    budget, unless ``best_effort`` (then the closest mesh is returned)."""
    v, f = _mesh_bytes(vertices, faces)
    p, t, _ = _roar.decimate(v, f, _budget(target_faces), bool(best_effort))
    return _arrays(p, t)


def init(
    vertices: Any,
    faces: Any,
    resolution: int = 0,
    max_faces: int = 20000,
) -> Tuple[np.ndarray, np.ndarray]:
    """The watertight, outward-oriented, self-intersection-free initial mesh of any soup (the
    CLI's ``roar init``), decimated to at most ``max_faces`` faces (even). ``resolution`` is the
    voxel count along the longest axis; 0 means the CLI's default."""
    v, f = _mesh_bytes(vertices, faces)
    return _arrays(*_roar.init(v, f, int(resolution), _budget(max_faces)))


def default_config() -> Dict[str, Any]:
    """The default configuration (the CLI's ``--print-config``) as a dict."""
    return json.loads(_roar.default_config())
