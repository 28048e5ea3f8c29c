"""Type stubs of the roar package (see the module docstring of roar/__init__.py)."""

import os
from typing import Any, Callable, Dict, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Progress = Callable[[Dict[str, Any]], None]

class RoarError(RuntimeError):
    """roar could not do the work asked (the message is the CLI's)."""

def reconstruct(
    vertices: npt.ArrayLike,
    faces: npt.ArrayLike,
    target_faces: int,
    config: Optional[Dict[str, Any]] = None,
    progress: Optional[_Progress] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], Dict[str, Any]]: ...
def reconstruct_file(
    path: _Path,
    target_faces: int,
    config: Optional[Dict[str, Any]] = None,
    progress: Optional[_Progress] = None,
    output: Optional[_Path] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], Dict[str, Any]]: ...
def reconstruct_sdf(
    f: Callable[[npt.NDArray[np.float64]], npt.ArrayLike],
    bounds: npt.ArrayLike,
    target_faces: int,
    gradient: Optional[Callable[[npt.NDArray[np.float64]], npt.ArrayLike]] = None,
    config: Optional[Dict[str, Any]] = None,
    progress: Optional[_Progress] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], Dict[str, Any]]: ...
def read_mesh(path: _Path) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]: ...
def eval(
    vertices: npt.ArrayLike,
    faces: npt.ArrayLike,
    reference: Optional[Tuple[npt.ArrayLike, npt.ArrayLike]] = None,
) -> Dict[str, Any]: ...
def decimate(
    vertices: npt.ArrayLike,
    faces: npt.ArrayLike,
    target_faces: int,
    best_effort: bool = False,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]: ...
def init(
    vertices: npt.ArrayLike,
    faces: npt.ArrayLike,
    resolution: int = 0,
    max_faces: int = 20000,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]: ...
def default_config() -> Dict[str, Any]: ...
