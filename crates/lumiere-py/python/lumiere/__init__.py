"""lumiere: a CPU Monte Carlo ray tracer, from Python.

    >>> import lumiere
    >>> image = lumiere.render(lumiere.builtin(), spp=16, size=(256, 192))
    >>> image.shape, image.dtype
    ((192, 256, 3), dtype('float32'))

:func:`load` and :func:`builtin` give a :class:`Scene` (or :meth:`Scene.from_arrays`), a
:class:`Camera` frames it, :func:`render` returns a float32 numpy array (``height, width, 3``),
:func:`denoise` cleans it with Intel Open Image Denoise (``pip install pyoidn``), and
:mod:`lumiere.distributed` splits a render across a Ray cluster with the same bytes
(``pip install ray``). Errors are :class:`LumiereError` (a ``ValueError``) or
:class:`LumiereOSError` (an ``OSError``) with the CLI's messages. See docs/PYTHON.md.
"""

from ._denoise import denoise
from ._lumiere import __version__
from ._render import AOVS, MODES, TECHNIQUE_OPTIONS, RenderResult, render, render_full
from ._scene import DEFAULT_SIZE, Camera, Scene, builtin, load
from .errors import LumiereError, LumiereOSError

__all__ = [
    "AOVS",
    "Camera",
    "DEFAULT_SIZE",
    "LumiereError",
    "LumiereOSError",
    "MODES",
    "RenderResult",
    "Scene",
    "TECHNIQUE_OPTIONS",
    "__version__",
    "builtin",
    "denoise",
    "load",
    "render",
    "render_full",
    "write_image",
]


def write_image(
    path: str, image: "object", exposure: float = 0.0, tonemap: str = "aces", *, aovs: "object" = None
) -> None:
    """Writes a ``(height, width, 3)`` float image as ``lumiere render -o`` does: ``.png``
    (exposure, ``aces`` or ``clamp`` tone mapping, sRGB), ``.exr`` or ``.pfm`` (linear), atomically.

    :param aovs: a dict of AOVs by name, as :func:`render` returns them (``albedo`` and ``normal``
        of the image's shape, ``depth`` of its height and width; ``color`` is left out): the extra
        channels of an ``.exr``, as ``lumiere render --aov`` writes them. ``noisy`` (the image's
        shape) is a layer of RGB channels, where ``lumiere render --denoise`` keeps the image
        before denoising.
    """
    import numpy as np

    array = _float32_array(image, "image")
    if array.ndim != 3 or array.shape[2] != 3:
        raise LumiereError(f"image must have shape (height, width, 3), got {array.shape}")
    height, width = array.shape[:2]
    # A side the writers' u32 cannot hold (an empty array can have one) is an error, not an overflow.
    if max(width, height) > 2**32 - 1:
        raise LumiereError(f"image size {width}x{height} is too large: at most 4294967295 pixels a side")
    layers = []
    if aovs is not None:
        if not isinstance(aovs, dict):
            raise TypeError(f"aovs must be a dict of arrays by AOV name, got {type(aovs).__name__}")
        for name in _aov_names([name for name in aovs if name != "color"]):
            layer = _float32_array(aovs[name], f"aovs[{name!r}]")
            # A depth is one number a pixel; the writer reads the first of three.
            if name == "depth" and layer.shape == (height, width):
                layer = np.repeat(layer[:, :, None], 3, axis=2)
            if layer.shape != (height, width, 3):
                expected = f"({height}, {width})" if name == "depth" else f"({height}, {width}, 3)"
                raise LumiereError(f"aovs[{name!r}] must have shape {expected} as the image, got {np.shape(aovs[name])}")
            layers.append((name, layer.tobytes()))
    exposure, tonemap = _float32(exposure, "exposure"), _text(tonemap, "tonemap")
    _write_image(_path(path), width, height, array.tobytes(), exposure, tonemap, layers)


from ._lumiere import write_image as _write_image  # noqa: E402
from ._render import _aov_names  # noqa: E402
from ._scene import _float32, _float32_array, _path, _text  # noqa: E402
