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
    "reconstruct_sdf",
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


class _Field:
    """The user's field as the compiled half calls it: ``(bytes of (n, 3) <f8 points,
    with_gradient) -> bytes`` of the n values (then the (n, 3) gradients), every result checked.
    Batches are numbered from 0 in the order they are asked for."""

    def __init__(self, f: Callable[[np.ndarray], Any], gradient: Optional[Callable]):
        self.f = f
        self.gradient = gradient
        self.batch = 0

    def __call__(self, data: bytes, with_gradient: bool) -> bytes:
        # A writable copy, so torch.from_numpy and in-place user code work.
        points = np.frombuffer(data, dtype="<f8").reshape(-1, 3).copy()
        batch = self.batch
        self.batch += 1
        n = len(points)
        values = self._checked("f", self.f(points), (n,), batch, points)
        if not with_gradient:
            return values.tobytes()
        gradients = self._checked("gradient", self.gradient(points), (n, 3), batch, points)
        return values.tobytes() + gradients.tobytes()

    @staticmethod
    def _checked(name, returned, shape, batch, points) -> np.ndarray:
        where = f"{name}: batch {batch} ({len(points)} points)"
        try:
            a = np.asarray(returned, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise ValueError(f"{where}: cannot read the result as float64: {e}") from None
        if a.shape != shape and not (len(shape) == 1 and a.shape == (shape[0], 1)):
            want = f"({shape[0]},)" if len(shape) == 1 else f"({shape[0]}, 3)"
            raise ValueError(f"{where}: returned shape {a.shape}, expected {want}")
        if not np.all(np.isfinite(a)):
            row = int(np.argwhere(~np.isfinite(a.reshape(shape[0], -1)))[0][0])
            raise ValueError(
                f"{where}: not finite at point {row} {tuple(points[row].tolist())}"
            )
        return np.ascontiguousarray(a.reshape(shape), dtype="<f8")


def _bounds(bounds: Any) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
    try:
        b = np.asarray(bounds, dtype=np.float64)
    except (TypeError, ValueError):
        b = None
    if b is None or b.shape != (2, 3):
        raise ValueError(f"bounds must be ((xmin, ymin, zmin), (xmax, ymax, zmax)), not {bounds!r}")
    if not np.all(np.isfinite(b)) or not np.all(b[1] > b[0]):
        raise ValueError(f"bounds must be finite with max > min on every axis, not {b.tolist()}")
    return tuple(b[0].tolist()), tuple(b[1].tolist())


def reconstruct_sdf(
    f: Callable[[np.ndarray], Any],
    bounds: Any,
    target_faces: int,
    gradient: Optional[Callable[[np.ndarray], Any]] = None,
    config: Optional[Dict[str, Any]] = None,
    progress: Optional[Callable[[Dict[str, Any]], None]] = None,
) -> Tuple[np.ndarray, np.ndarray, Dict[str, Any]]:
    """Reconstructs the zero set of a signed distance function (negative inside) within
    ``bounds = ((xmin, ymin, zmin), (xmax, ymax, zmax))`` as a closed, oriented 2-manifold with
    exactly ``target_faces`` faces, with the CLI's SDF schedule.

    ``f`` maps a float64 ``(n, 3)`` array to ``n`` values (anything ``np.asarray`` reads: wrap a
    PyTorch or JAX model in a line, e.g. ``lambda p: model(torch.from_numpy(p)).detach().numpy()``).
    roar samples the field once, adaptively, calling ``f`` on batches of up to 16,384 points,
    one at a time; every later stage reads the samples. ``gradient``, if given, maps the same
    array to the ``(n, 3)`` gradients; without it, gradients are differences of the samples (no
    extra calls; ``{"target": {"sdf_sample": False}}``, which has every stage evaluate the field,
    needs ``gradient``). The field need not be distance-scaled.

    An exception raised by ``f``, ``gradient`` or ``progress`` propagates as itself; a result of
    the wrong shape, or one that is not finite, is a ``ValueError`` naming the batch and point.
    Ctrl-C takes effect at the next progress report (the sampling is one stage).

    Returns ``(vertices, faces, report)``; ``report["sdf"]`` counts the field's evaluations by
    stage (``values``, ``gradients``) and the sampling's figures.
    """
    if not callable(f):
        raise ValueError("f must be callable")
    if gradient is not None and not callable(gradient):
        raise ValueError("gradient must be callable")
    if progress is not None and not callable(progress):
        raise ValueError("progress must be callable")
    lo, hi = _bounds(bounds)
    faces_wanted = _budget(target_faces)
    p, t, report = _roar.reconstruct_sdf(
        _Field(f, gradient),
        gradient is not None,
        (lo, hi),
        faces_wanted,
        _config_json(config),
        progress,
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
