"""Scenes and cameras: thin wrappers over the native objects that remember how they were made, so
that they pickle (Ray ships them to workers, which rebuild them) and print helpfully."""

from __future__ import annotations

import math
import os
import sys
import uuid
import warnings
from collections import OrderedDict
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _lumiere
from .errors import LumiereError

__all__ = ["Scene", "Camera", "load", "builtin", "DEFAULT_SIZE"]

PathLike = Union[str, "os.PathLike[str]"]
Vector = Sequence[float]

#: The image size of the lab (and of ``lumiere render``): 1024x768, as (width, height).
DEFAULT_SIZE: Tuple[int, int] = (1024, 768)

#: The largest finite float32: the native side's numbers.
_F32_MAX = float(np.finfo(np.float32).max)


def _emission_list(emission: Optional[Mapping[str, Vector]]) -> list:
    if emission is None:
        return []
    if not isinstance(emission, Mapping):
        raise LumiereError("emission must be a dict {material name: (r, g, b)}")
    return [(_text(name, "emission name"), _vector(value, f"emission[{name!r}]")) for name, value in emission.items()]


def _vector(value: Any, what: str) -> Tuple[float, float, float]:
    try:
        # A string is a sequence too: "111" is not (1, 1, 1).
        if isinstance(value, (str, bytes)) or any(isinstance(v, (str, bytes)) for v in value):
            raise TypeError
        x, y, z = (float(v) for v in value)
    except (TypeError, ValueError):
        raise LumiereError(f"{what} must be three numbers, got {value!r}") from None
    except OverflowError:
        # An integer beyond float64's range: beyond float32's too (its digits are not worth printing).
        raise LumiereError(f"{what} must fit in float32 (at most {_F32_MAX:.7g} in magnitude)") from None
    if any(not _fits_float32(v) for v in (x, y, z)):
        raise LumiereError(f"{what} must fit in float32 (at most {_F32_MAX:.7g} in magnitude), got {value!r}")
    return (x, y, z)


def _fits_float32(value: float) -> bool:
    """Whether ``value`` reaches the native side, which stores float32, as itself: a finite number
    beyond its range would arrive as infinity and be refused under another value (infinity and NaN
    are left to the native side's own checks)."""
    return not (math.isfinite(value) and abs(value) > _F32_MAX)


def _float32(value: Any, what: str) -> float:
    """:func:`_number` for a number the native side takes as float32."""
    number = _number(value, what)
    if not _fits_float32(number):
        raise LumiereError(f"{what} must fit in float32 (at most {_F32_MAX:.7g} in magnitude), got {value!r}")
    return number


def _float32_array(values: Any, what: str) -> np.ndarray:
    """``values`` as a contiguous float32 array, if it holds numbers: an object array's None (or
    a string of digits) would be converted silently, None to NaN, and a complex value would lose
    its imaginary part. Values beyond float32 become infinities, as the CLI's would (numpy's
    overflow warning would point at this line, not the caller's)."""
    values = np.asarray(values)
    if values.dtype.kind not in "buif":
        raise LumiereError(f"{what} must hold numbers, got an array of {values.dtype}")
    with np.errstate(over="ignore"):
        return np.ascontiguousarray(values, dtype=np.float32)


def _number(value: Any, what: str) -> float:
    """``value`` as a float, if it is a number (not a bool, not a string such as "45")."""
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise LumiereError(f"{what} must be a number, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise LumiereError(f"{what} must be a number, got {value!r}") from None
    except OverflowError:
        # An integer beyond float64's range (its digits are not worth printing).
        raise LumiereError(f"{what} must be at most {sys.float_info.max:.7g} in magnitude") from None


def _text(value: Any, what: str) -> str:
    """``value`` if it is a ``str`` the native side can take (UTF-8: no lone surrogates, which
    ``os.fsdecode`` makes of undecodable bytes)."""
    if not isinstance(value, str):
        raise LumiereError(f"{what} must be a string, got {value!r}")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        raise LumiereError(f"{what} must be valid Unicode text, got {value!r}") from None
    return value


def _path(path: Any) -> str:
    """A path given as ``str``, ``bytes`` or ``os.PathLike``, as the ``str`` the native side takes."""
    try:
        return os.fsdecode(os.fspath(path))
    except TypeError:
        raise TypeError(f"a path must be a str, bytes or os.PathLike, got {type(path).__name__}") from None


def _integer(value: Any, what: str, low: int, high: Optional[int] = None) -> int:
    """`value` as an int, if it is an integer (a numpy integer too; not a bool, not a float) in
    [low, high] (no upper bound for None): the native side takes fixed-size integers, which must
    not overflow or truncate."""
    if high is None:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or int(value) < low:
            raise LumiereError(f"{what} must be an integer of at least {low}, got {value!r}")
        return int(value)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise LumiereError(f"{what} must be an integer, got {value!r}")
    if not low <= int(value) <= high:
        raise LumiereError(f"{what} must be between {low} and {high}, got {value!r}")
    return int(value)


def _first_repeat(items: Sequence[Any]) -> Optional[Any]:
    """The first item given a second time, or None: an option named twice, which the CLI refuses."""
    return next((item for i, item in enumerate(items) if item in items[:i]), None)


def _own_array(value: Any, dtype: Any, what: str) -> np.ndarray:
    """A C-contiguous copy of ``value`` as ``dtype``, read-only: a scene's recipe must not share
    the caller's buffer, which the caller may change after the scene is made (numpy's
    ``ascontiguousarray`` returns the very array when it already fits)."""
    try:
        given = np.asarray(value)
        # Real numbers only: strings of digits and complex numbers were converted (the imaginary
        # part dropped, with numpy's warning pointing here), as write_image refuses them.
        if given.dtype.kind not in "buif":
            raise TypeError
        # Values beyond the type become infinities, refused by name later, without numpy's
        # overflow warning pointing at this line.
        with np.errstate(over="ignore"):
            array = np.array(given, dtype=dtype, order="C", copy=True)
    except (TypeError, ValueError, OverflowError):
        raise LumiereError(f"{what} must be an array of numbers") from None
    array.flags.writeable = False
    return array


def _size(size: Any) -> Tuple[int, int]:
    try:
        width, height = size
    except (TypeError, ValueError):
        raise LumiereError(f"size must be (width, height), got {size!r}") from None
    width, height = (_integer(v, "size", 0, 2**32 - 1) for v in (width, height))
    if width <= 0 or height <= 0:
        raise LumiereError(f"image size {width}x{height} has no pixels")
    return (width, height)


class Scene:
    """A scene ready to render: triangles, materials, and the BVH and lights built from them.

    Make one with :func:`lumiere.load` (an OBJ or PLY file), :func:`lumiere.builtin` (gKit's Cornell box)
    or :meth:`Scene.from_arrays` (numpy arrays). Scenes pickle by recipe: the unpickling process
    loads the file again (it must see the same file) or rebuilds the arrays.
    """

    __slots__ = ("_native", "_recipe")

    def __init__(self, native: "_lumiere.NativeScene", recipe: tuple) -> None:
        self._native = native
        self._recipe = recipe

    @classmethod
    def from_arrays(
        cls,
        vertices: Any,
        triangles: Any,
        materials: Optional[Sequence[Union[str, Mapping[str, Any]]]] = None,
        material_ids: Any = None,
        normals: Any = None,
        name: str = "arrays",
    ) -> "Scene":
        """A scene from numpy arrays.

        :param vertices: positions, shape ``(N, 3)``, any float type (stored as float32).
        :param triangles: vertex indices, shape ``(M, 3)``, integers in ``[0, N)``.
        :param materials: a list of materials, each a name or a dict with ``name``, ``kd``
            (diffuse colour, default 0.8 grey) and ``ke`` (emitted radiance: a light). Default: one
            grey material.
        :param material_ids: the material of each triangle, shape ``(M,)``; default all 0.
        :param normals: optional per-vertex shading normals, shape ``(N, 3)``.

        The arrays are copied: changing them afterwards changes neither the scene nor its pickles
        (which rebuild it from the copies).
        """
        name = _text(name, "name")
        vertices = _own_array(vertices, np.float32, "vertices")
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise LumiereError(f"vertices must have shape (N, 3), got {vertices.shape}")
        triangles = np.asarray(triangles)
        if triangles.size == 0 and triangles.dtype.kind in "biuf":
            # `[]` (numpy reads it as float64, shape (0,)): no triangles, a scene of vertices only.
            triangles = np.zeros((0, 3), dtype=np.uint32)
        if triangles.ndim != 2 or triangles.shape[1] != 3 or not np.issubdtype(triangles.dtype, np.integer):
            raise LumiereError(f"triangles must be integers of shape (M, 3), got {triangles.dtype} {triangles.shape}")
        if triangles.size and (triangles.min() < 0 or triangles.max() >= len(vertices)):
            raise LumiereError(f"triangles index vertices 0..{len(vertices) - 1}, found {triangles.min()}..{triangles.max()}")
        triangles = _own_array(triangles, np.uint32, "triangles")
        if isinstance(materials, (str, bytes, Mapping)):
            raise LumiereError(f"materials must be a list of names or dicts, got {materials!r}")
        if materials is not None:
            try:
                materials = list(materials)
            except TypeError:
                raise LumiereError(f"materials must be a list of names or dicts, got {materials!r}") from None
        # Named for what it is, not as "material id 0 out of range": every triangle needs one.
        if materials is not None and len(triangles) > 0 and len(materials) == 0:
            raise LumiereError("materials must name at least one material (material_ids index it; 0 by default)")
        specs = []
        for index, material in enumerate(materials if materials is not None else ["default"]):
            if isinstance(material, str):
                material = {"name": material}
            if not isinstance(material, Mapping) or "name" not in material:
                raise LumiereError(f"materials[{index}] must be a name or a dict with a 'name', got {material!r}")
            unknown = set(material) - {"name", "kd", "ke"}
            if unknown:
                raise LumiereError(f"materials[{index}]: unknown keys {sorted(unknown)} (known: name, kd, ke)")
            kd = _vector(material.get("kd", (0.8, 0.8, 0.8)), f"materials[{index}]['kd']")
            ke = _vector(material.get("ke", (0.0, 0.0, 0.0)), f"materials[{index}]['ke']")
            specs.append((_text(material["name"], f"materials[{index}]['name']"), kd, ke))
        if material_ids is None:
            ids = np.zeros(len(triangles), dtype=np.uint32)
        else:
            ids = np.asarray(material_ids)
            if ids.shape != (len(triangles),) or not np.issubdtype(ids.dtype, np.integer):
                raise LumiereError(f"material_ids must be {len(triangles)} integers, got {ids.dtype} {ids.shape}")
            if ids.size and (ids.min() < 0 or ids.max() >= len(specs)):
                raise LumiereError(f"material_ids index materials 0..{len(specs) - 1}, found {ids.min()}..{ids.max()}")
            ids = _own_array(ids, np.uint32, "material_ids")
        if normals is not None:
            normals = _own_array(normals, np.float32, "normals")
            if normals.shape != vertices.shape:
                raise LumiereError(f"normals must have the shape of vertices {vertices.shape}, got {normals.shape}")
        native = _lumiere.NativeScene.from_arrays(
            name,
            vertices.tobytes(),
            triangles.tobytes(),
            ids.tobytes(),
            specs,
            None if normals is None else normals.tobytes(),
        )
        recipe = ("arrays", vertices, triangles, specs, ids, normals, name, uuid.uuid4().hex)
        return _made(native, recipe)

    def info(self) -> Dict[str, Any]:
        """What ``lumiere info`` prints: ``name``, ``triangles``, ``vertices``, ``materials`` (by
        name: ``triangles``, ``kd``, ``ke``, ``texture``, ``cutout`` (its ``map_d`` mask),
        ``light``), ``lights`` (``triangles``, ``area``, ``power``), ``bounds`` (``(min, max)`` or
        None), ``view`` (see :attr:`view`), ``warnings``, load and build seconds."""
        return self._native.info()

    @property
    def view(self) -> Optional[Dict[str, Any]]:
        """The view the scene file gives itself, which :func:`lumiere.render` uses with
        ``camera=None``: a glTF file's first perspective camera, as a new dict of ``eye``,
        ``target``, ``up`` (tuples), ``fov`` (vertical, degrees) and ``name`` (None if unnamed);
        None for OBJ, PLY, arrays, the built-in scene and glTF files without a camera."""
        return self._native.view

    @property
    def name(self) -> str:
        return self._native.name

    @property
    def warnings(self) -> list:
        """Non-fatal problems met while loading (a missing MTL file, an unknown material) and
        building (a texture that cannot be read or decoded), as ``lumiere render`` prints them;
        each was also issued as a Python warning when the scene was made."""
        return self._native.warnings

    @property
    def fingerprint(self) -> int:
        """A hash of the geometry and materials (emission included), as checkpoints store it."""
        return self._native.fingerprint

    @property
    def is_builtin(self) -> bool:
        return self._native.builtin

    @property
    def _file(self) -> Optional[str]:
        """The file the scene was loaded from; None for the built-in scene and arrays."""
        return self._recipe[1] if self._recipe[0] == "load" else None

    def __reduce__(self) -> tuple:
        return (_rebuild_scene, (self._recipe,))

    def __repr__(self) -> str:
        return repr(self._native)


#: Scenes rebuilt from pickles, by recipe: a Ray worker that runs many tasks of one render loads
#: its scene (and builds its BVH) once. A few are kept, the least recently used dropped.
_SCENES: "OrderedDict[tuple, _lumiere.NativeScene]" = OrderedDict()
_SCENES_KEPT = 4


_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _stacklevel_outside() -> int:
    """The ``stacklevel`` that makes a warning issued in the calling function point at the first
    line outside this package that led to it: the user's call, whichever of the package's
    functions it went through (:func:`render` calls :func:`render_full`, for one)."""
    level, frame = 1, sys._getframe(1)
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE):
        level, frame = level + 1, frame.f_back
    return level


def _made(native: "_lumiere.NativeScene", how: tuple) -> Scene:
    """A scene made in this process from ``how`` (a recipe less the fingerprint), its warnings
    issued as the CLI prints them. The recipe records the fingerprint, so that a process
    rebuilding it can tell a scene it cached from an older version of the file (see
    :func:`_rebuild_scene`)."""
    for message in native.warnings:
        warnings.warn(message, stacklevel=_stacklevel_outside())
    return Scene(native, (*how, native.fingerprint))


def _rebuild_scene(recipe: tuple) -> Scene:
    kind, fingerprint = recipe[0], recipe[-1]
    if kind == "load":
        key: tuple = (kind, recipe[1], tuple(recipe[2]))
    elif kind == "arrays":
        key = (kind, recipe[-2])
    else:
        raise LumiereError(f"unknown scene recipe {kind!r}")
    native = _SCENES.get(key)
    # A scene cached from the file before it was edited is loaded again (its fingerprint is not
    # the one the maker of the recipe saw); a mismatch left after that is for the driver to report.
    if native is None or native.fingerprint != fingerprint:
        if kind == "load":
            native = _lumiere.NativeScene.load(recipe[1], list(recipe[2]))
        else:
            _, vertices, triangles, specs, ids, normals, name, _, _ = recipe
            native = _lumiere.NativeScene.from_arrays(
                name, vertices.tobytes(), triangles.tobytes(), ids.tobytes(), specs, None if normals is None else normals.tobytes()
            )
        _SCENES[key] = native
        while len(_SCENES) > _SCENES_KEPT:
            _SCENES.popitem(last=False)
    _SCENES.move_to_end(key)
    return Scene(native, recipe)


def load(path: PathLike, emission: Optional[Mapping[str, Vector]] = None) -> Scene:
    """Loads a scene file: Wavefront OBJ (``.obj`` or ``.obj.gz``, with its MTL files and
    textures), glTF 2.0 (``.gltf`` with its buffers and images, or ``.glb``: its node tree,
    meshes, metallic-roughness materials and first perspective camera, :attr:`Scene.view`) or
    PLY (``.ply`` or ``.ply.gz``: its vertices, normals and faces, with one grey material named
    ``default``).

    :param emission: sets the emitted radiance of materials by name, as ``--emission`` does:
        ``{"Light": (17, 12, 4)}``; a name the scene lacks is an error.
    :raises LumiereOSError: the file cannot be read.
    :raises LumiereError: the file is malformed (the message names the file and line).
    """
    path = os.path.abspath(_path(path))
    emission = _emission_list(emission)
    return _made(_lumiere.NativeScene.load(path, emission), ("load", path, emission))


def builtin(emission: Optional[Mapping[str, Vector]] = None) -> Scene:
    """gKit's Cornell box, embedded in lumiere (what ``lumiere render`` renders without a scene).
    With ``camera=None``, :func:`lumiere.render` uses its orbiter camera."""
    emission = _emission_list(emission)
    return _made(_lumiere.NativeScene.load(None, emission), ("load", None, emission))


class Camera:
    """A camera and the image size it renders, ``size = (width, height)`` in pixels.

    Pickles by recipe (an orbiter keeps the file's text, so workers need no copy of it).
    """

    __slots__ = ("_native", "_recipe")

    def __init__(self, native: "_lumiere.NativeCamera", recipe: tuple) -> None:
        self._native = native
        self._recipe = recipe

    @classmethod
    def look_at(
        cls,
        eye: Vector,
        target: Vector,
        up: Vector = (0.0, 1.0, 0.0),
        fov: float = 45.0,
        size: Tuple[int, int] = DEFAULT_SIZE,
    ) -> "Camera":
        """A pinhole at ``eye`` looking at ``target``, ``fov`` the vertical field of view in degrees
        (``--eye/--target/--up/--fov`` of the CLI)."""
        args = (_vector(eye, "eye"), _vector(target, "target"), _vector(up, "up"), _float32(fov, "fov"), *_size(size))
        return cls(_lumiere.NativeCamera.look_at(*args), ("look_at", args))

    @classmethod
    def orbiter(cls, path: PathLike, size: Tuple[int, int] = DEFAULT_SIZE) -> "Camera":
        """gKit's orbiter camera from an orbiter file (``--orbiter``)."""
        path = _path(path)
        # As lumiere.load and --orbiter read files: a regular file only (a FIFO would block, a
        # device such as /dev/zero never end), never past its size.
        args = (_lumiere.read_input(path), path, *_size(size))
        return cls(_lumiere.NativeCamera.orbiter(*args), ("orbiter", args))

    @classmethod
    def builtin(cls, size: Tuple[int, int] = DEFAULT_SIZE) -> "Camera":
        """The built-in scene's camera: gKit's 2022 orbiter of the Cornell box."""
        args = _size(size)
        return cls(_lumiere.NativeCamera.builtin(*args), ("builtin", args))

    @classmethod
    def framing(
        cls, scene: Scene, size: Tuple[int, int] = DEFAULT_SIZE, fov: float = 45.0, up: Vector = (0.0, 1.0, 0.0)
    ) -> "Camera":
        """A look-at view from +z that frames the whole scene: the CLI's camera for a scene file
        given without one."""
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a lumiere.Scene, got {type(scene).__name__}")
        eye, target = _lumiere.NativeCamera.framing(scene._native, _float32(fov, "fov"))
        return cls.look_at(eye, target, up, fov, size)

    @classmethod
    def scene_view(cls, scene: Scene, size: Tuple[int, int] = DEFAULT_SIZE) -> "Camera":
        """The look-at camera of the view the scene file gives itself (:attr:`Scene.view`, a glTF
        camera): what :func:`lumiere.render` and the CLI use for such a scene given without a
        camera. ``size`` decides the horizontal field of view (the file's aspect ratio is not read).

        :raises LumiereError: the scene has no view of its own.
        """
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a lumiere.Scene, got {type(scene).__name__}")
        view = scene.view
        if view is None:
            raise LumiereError(f"{scene.name}: the scene has no view of its own (no glTF camera); use Camera.framing")
        # Made as a look-at, so that it pickles without the scene.
        return cls.look_at(view["eye"], view["target"], view["up"], view["fov"], size)

    @property
    def size(self) -> Tuple[int, int]:
        """``(width, height)``; the rendered array has shape ``(height, width, 3)``."""
        return (self._native.width, self._native.height)

    @property
    def width(self) -> int:
        return self._native.width

    @property
    def _file(self) -> Optional[str]:
        """The orbiter file the camera was read from; None for other cameras."""
        kind, args = self._recipe
        return args[1] if kind == "orbiter" else None

    @property
    def height(self) -> int:
        return self._native.height

    def __reduce__(self) -> tuple:
        return (_rebuild_camera, (self._recipe,))

    def __repr__(self) -> str:
        kind, args = self._recipe
        if kind == "orbiter":
            return f"Camera.orbiter({args[1]!r}, size={self.size})"
        if kind == "builtin":
            return f"Camera.builtin(size={self.size})"
        eye, target, up, fov = args[:4]
        return f"Camera.look_at(eye={eye}, target={target}, up={up}, fov={fov}, size={self.size})"


def _rebuild_camera(recipe: tuple) -> Camera:
    kind, args = recipe
    factory = {
        "look_at": _lumiere.NativeCamera.look_at,
        "orbiter": _lumiere.NativeCamera.orbiter,
        "builtin": _lumiere.NativeCamera.builtin,
    }[kind]
    return Camera(factory(*args), recipe)
