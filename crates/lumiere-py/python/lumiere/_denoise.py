"""``lumiere.denoise``: Intel Open Image Denoise through ``pyoidn`` (which ships the OIDN library
itself), an optional dependency: ``pip install pyoidn``."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ._scene import _float32_array
from .errors import LumiereError

__all__ = ["denoise"]

#: OIDN's filter qualities, best first.
QUALITIES = ("high", "balanced", "fast")


def _pyoidn() -> Any:
    try:
        import pyoidn
    except ImportError as e:
        raise ImportError(
            "lumiere.denoise needs pyoidn (Intel Open Image Denoise): pip install pyoidn"
        ) from e
    return pyoidn


def _image(value: Any, name: str, shape: Optional[tuple]) -> np.ndarray:
    # Numbers only, as lumiere.write_image takes them.
    array = _float32_array(value, name)
    if array.ndim != 3 or array.shape[2] != 3 or min(array.shape[:2]) == 0:
        raise LumiereError(f"{name} must have shape (height, width, 3), got {array.shape}")
    if shape is not None and array.shape != shape:
        raise LumiereError(f"{name} has shape {array.shape} but color has {shape}")
    return array


def denoise(color: Any, albedo: Any = None, normal: Any = None, *, quality: str = "high") -> np.ndarray:
    """Denoises a linear HDR render with OIDN's ``RT`` filter and returns a new float32 array.

    :param color: linear RGB radiance ``(height, width, 3)``, as :func:`lumiere.render` returns.
    :param albedo: optional first-hit albedo (``aovs=("albedo",)``): sharper edges and textures.
    :param normal: optional first-hit normals (``aovs=("normal",)``, needs ``albedo`` too).
    :param quality: ``high``, ``balanced`` or ``fast``.
    :raises ImportError: pyoidn is not installed (the message says how to install it).
    """
    if quality not in QUALITIES:
        raise LumiereError(f"quality must be one of {', '.join(QUALITIES)}, got {quality!r}")
    color = _image(color, "color", None)
    if normal is not None and albedo is None:
        raise LumiereError("normal needs albedo too (OIDN uses normals only with an albedo)")
    albedo = None if albedo is None else _image(albedo, "albedo", color.shape)
    normal = None if normal is None else _image(normal, "normal", color.shape)
    return _pyoidn().denoise(color, albedo, normal, hdr=True, quality=quality)
