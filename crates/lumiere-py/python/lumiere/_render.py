"""``lumiere.render``: a scene and a camera in, a float32 numpy image out (plus AOVs on request)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Optional, Sequence, Tuple, Union

import numpy as np

from . import _lumiere
from ._scene import DEFAULT_SIZE, Camera, Scene, _first_repeat, _float32, _integer, _number, _stacklevel_outside, _text
from .errors import LumiereError

__all__ = ["render", "render_full", "RenderResult", "MODES", "AOVS", "TECHNIQUE_OPTIONS"]

#: What a pixel shows: path tracing (the default), or one of the lab's steps.
MODES = ("path", "hits", "materials", "shadows", "direct", "ao")
#: The arbitrary outputs :func:`render` can add: first-hit albedo, normal and depth.
AOVS = ("albedo", "normal", "depth")
#: Options of particular techniques, passed to :func:`render` as keywords.
TECHNIQUE_OPTIONS = ("samples", "light_sampling", "ao_distance", "max_depth")

Progress = Callable[[int, Optional[int]], Any]


@dataclass(frozen=True)
class RenderResult:
    """Everything a render produced."""

    #: Linear RGB radiance, float32, shape ``(height, width, 3)``, row 0 at the top.
    image: np.ndarray
    #: The AOVs asked for, by name: ``albedo`` and ``normal`` ``(height, width, 3)``,
    #: ``depth`` ``(height, width)``.
    aovs: Dict[str, np.ndarray] = field(default_factory=dict)
    #: ``samples`` per pixel, ``rays``, ``seconds`` (rendering only), ``mrays_per_second``,
    #: ``stop`` (why it stopped), ``discarded`` (invalid samples), ``threads``, ``relative_error``.
    stats: Dict[str, Any] = field(default_factory=dict)


def _array(buffer: bytearray, height: int, width: int) -> np.ndarray:
    # A view of the bytearray the renderer filled: no copy, writable.
    return np.frombuffer(buffer, dtype=np.float32).reshape(height, width, 3)


def _check_progress(progress: Optional[Progress]) -> None:
    """Refuses, before any work, a progress callback that cannot be called (found out otherwise
    only once passes have been rendered)."""
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable as progress(done, total), got {type(progress).__name__}")


def _options(
    mode: str,
    spp: Optional[int],
    seed: int,
    sampler: Optional[str],
    time: Optional[float],
    noise: Optional[float],
    technique_options: Dict[str, Any],
) -> "_lumiere.NativeOptions":
    unknown = set(technique_options) - set(TECHNIQUE_OPTIONS)
    if unknown:
        raise TypeError(
            f"render() got unexpected keyword arguments {sorted(unknown)}; technique options are {', '.join(TECHNIQUE_OPTIONS)}"
        )
    time = None if time is None else _number(time, "time")
    noise = None if noise is None else _number(noise, "noise")
    seed = _integer(seed, "seed", 0, 2**64 - 1)
    # 2**32 - 1 is the native side's "until a budget stops it", which spp=None asks for.
    spp = None if spp is None else _integer(spp, "spp", 1, 2**32 - 2)
    # Checked in place: lumiere.distributed ships the checked values to its workers.
    for name, low in (("samples", 1), ("max_depth", 0)):
        if technique_options.get(name) is not None:
            technique_options[name] = _integer(technique_options[name], name, low, 2**32 - 1)
    if technique_options.get("ao_distance") is not None:
        technique_options["ao_distance"] = _float32(technique_options["ao_distance"], "ao_distance")
    if technique_options.get("light_sampling") is not None:
        technique_options["light_sampling"] = _text(technique_options["light_sampling"], "light_sampling")
    mode = _text(mode, "mode")
    sampler = None if sampler is None else _text(sampler, "sampler")
    options = _lumiere.NativeOptions(mode, spp, seed, sampler, time=time, noise=noise, **technique_options)
    for message in options.ignored:
        warnings.warn(message, stacklevel=_stacklevel_outside())
    return options


def _check_scene(scene: Any) -> None:
    """Refuses what cannot be rendered: not a :class:`Scene`, or a scene without a face."""
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a lumiere.Scene (lumiere.load, lumiere.builtin), got {type(scene).__name__}")
    scene._native.check_has_faces()


def _camera(scene: Scene, camera: Optional[Camera], size: Optional[Tuple[int, int]]) -> Camera:
    if camera is not None:
        if size is not None:
            raise LumiereError("size applies only when camera is None: the camera has its own size")
        if not isinstance(camera, Camera):
            raise TypeError(f"camera must be a lumiere.Camera, got {type(camera).__name__}")
        return camera
    size = DEFAULT_SIZE if size is None else size
    if scene.is_builtin:
        return Camera.builtin(size)
    return Camera.framing(scene, size) if scene.view is None else Camera.scene_view(scene, size)


def _threads(threads: int) -> int:
    # 0 is RAYON_NUM_THREADS or one per core; at most 1024, as the CLI's --threads.
    return _integer(threads, "threads (0 for one per core)", 0, 1024)


def render_full(
    scene: Scene,
    camera: Optional[Camera] = None,
    mode: str = "path",
    spp: Optional[int] = 64,
    seed: int = 0,
    threads: int = 0,
    *,
    sampler: Optional[str] = None,
    size: Optional[Tuple[int, int]] = None,
    aovs: Sequence[str] = (),
    progress: Optional[Progress] = None,
    time: Optional[float] = None,
    noise: Optional[float] = None,
    **technique_options: Any,
) -> RenderResult:
    """Like :func:`render`, returning the image, the AOVs and the statistics together."""
    _check_scene(scene)
    options = _options(mode, spp, seed, sampler, time, noise, technique_options)
    camera = _camera(scene, camera, size)
    aovs = _aov_names(aovs)
    _check_progress(progress)
    # The warnings the render issues (a noise target out of reach) point at the user's call.
    image, buffers, stats = _lumiere.render(
        scene._native, camera._native, options, _threads(threads), list(aovs), progress, _stacklevel_outside()
    )
    height, width = camera.height, camera.width
    return RenderResult(_array(image, height, width), _aov_arrays(aovs, buffers, height, width), stats)


def _aov_names(aovs: Any) -> Tuple[str, ...]:
    """The AOV names asked for (one name alone, or None for none), each once."""
    if isinstance(aovs, str):
        aovs = (aovs,)
    if aovs is None:
        aovs = ()
    try:
        names = tuple(_text(aov, f"aovs[{index}]") for index, aov in enumerate(aovs))
    except TypeError:
        raise LumiereError(f"aovs must be a list of names (albedo, normal, depth), got {aovs!r}") from None
    # An EXR cannot hold a channel twice, and the CLI refuses it: so does this.
    twice = _first_repeat(names)
    if twice is not None:
        raise LumiereError(f"aov {twice!r} is given twice")
    return names


def _aov_arrays(names: Sequence[str], buffers: Sequence[bytearray], height: int, width: int) -> Dict[str, np.ndarray]:
    """The library's AOV buffers as arrays by name: depth is one number per pixel (the library
    repeats it in three channels), the others three."""
    arrays = {}
    for name, buffer in zip(names, buffers):
        array = _array(buffer, height, width)
        arrays[name] = array[:, :, 0].copy() if name == "depth" else array
    return arrays


def render(
    scene: Scene,
    camera: Optional[Camera] = None,
    mode: str = "path",
    spp: Optional[int] = 64,
    seed: int = 0,
    threads: int = 0,
    *,
    sampler: Optional[str] = None,
    size: Optional[Tuple[int, int]] = None,
    aovs: Sequence[str] = (),
    progress: Optional[Progress] = None,
    time: Optional[float] = None,
    noise: Optional[float] = None,
    **technique_options: Any,
) -> Union[np.ndarray, Dict[str, np.ndarray]]:
    """Renders ``scene`` and returns linear RGB radiance as a float32 array ``(height, width, 3)``,
    row 0 at the top: the values ``lumiere render -o image.pfm`` writes for the same options.

    :param camera: a :class:`Camera`; None: the built-in scene's orbiter for
        :func:`lumiere.builtin`, the scene file's own view where it has one (:attr:`Scene.view`,
        a glTF camera), a view framing the scene otherwise (all ``size`` pixels, default
        1024x768).
    :param mode: ``path`` (global illumination), or the lab's ``hits``, ``materials``,
        ``shadows``, ``direct``, ``ao``.
    :param spp: camera samples per pixel (1 = the lab's pixel centres, more are jittered). None
        renders until ``time`` or ``noise`` stops it.
    :param seed: same seed, same values, whatever ``threads``.
    :param threads: worker threads, 0 = ``RAYON_NUM_THREADS`` if set, else all cores; at most 1024.
    :param sampler: ``independent`` or ``sobol``; by default ``sobol`` for path, ``independent`` for
        the lab's modes (as the CLI).
    :param aovs: names among ``albedo``, ``normal``, ``depth``: the result is then a dict with
        ``color`` and each AOV.
    :param progress: called as ``progress(done, total)`` in pixel samples, from the calling
        thread, every few milliseconds while samples are added (``total`` is None with a budget).
        An exception it raises stops the render and propagates.
    :param time: stop after the pass that crosses this many seconds.
    :param noise: stop once the estimated relative error is below this. A target more than an
        hour away at the render's rate, that neither ``spp`` nor ``time`` stops it before, is one
        ``RuntimeWarning`` early on (the render goes on).
    :param technique_options: ``samples`` (direct, ao: points per light or directions; default
        16), ``light_sampling`` (direct: ``per-light`` or ``power``), ``ao_distance`` (ao),
        ``max_depth`` (path: segments from the camera, default 8, 0 = no limit).

    The GIL is released while rendering; Ctrl-C stops the render within milliseconds and raises
    :class:`KeyboardInterrupt`.

    :raises LumiereError: a bad option (with the CLI's message); a :class:`LumiereOSError` for files.
    """
    result = render_full(
        scene,
        camera,
        mode,
        spp,
        seed,
        threads,
        sampler=sampler,
        size=size,
        aovs=aovs,
        progress=progress,
        time=time,
        noise=noise,
        **technique_options,
    )
    if not result.aovs and not aovs:
        return result.image
    return {"color": result.image, **result.aovs}
