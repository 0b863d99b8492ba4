"""Type stubs of the native module ``lumiere._lumiere`` (Rust, PyO3). Use the public API in
``lumiere`` instead: it wraps these with numpy arrays, keyword options and pickling."""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

__version__: str

_Path = Union[str, PathLike[str]]
_Vec3 = Tuple[float, float, float]
_Progress = Callable[[int, Optional[int]], Any]

class NativeScene:
    """A scene with its BVH and lights built."""

    builtin: bool
    fingerprint: int
    load_seconds: float
    build_seconds: float
    @property
    def name(self) -> str: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def view(self) -> Optional[Dict[str, Any]]:
        """The scene file's own view (a glTF camera): eye, target, up, fov (degrees), name."""
    @staticmethod
    def load(path: Optional[_Path], emission: Sequence[Tuple[str, _Vec3]]) -> NativeScene:
        """An OBJ file, or the built-in Cornell box when ``path`` is None; emission applied."""
    @staticmethod
    def from_arrays(
        name: str,
        positions: bytes,
        indices: bytes,
        material_ids: bytes,
        materials: Sequence[Tuple[str, _Vec3, _Vec3]],
        normals: Optional[bytes] = None,
    ) -> NativeScene:
        """float32 positions, uint32 indices and ids (native endian); materials (name, kd, ke)."""
    def info(self) -> Dict[str, Any]: ...

class NativeCamera:
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @staticmethod
    def look_at(eye: _Vec3, target: _Vec3, up: _Vec3, fov: float, width: int, height: int) -> NativeCamera: ...
    @staticmethod
    def orbiter(text: bytes, path: _Path, width: int, height: int) -> NativeCamera: ...
    @staticmethod
    def builtin(width: int, height: int) -> NativeCamera: ...
    @staticmethod
    def framing(scene: NativeScene, fov: float) -> Tuple[_Vec3, _Vec3]:
        """The eye and target of the view that frames ``scene``."""

class NativeOptions:
    ignored: List[str]
    def __init__(
        self,
        mode: str,
        spp: Optional[int],
        seed: int,
        sampler: Optional[str],
        samples: Optional[int] = None,
        light_sampling: Optional[str] = None,
        ao_distance: Optional[float] = None,
        max_depth: Optional[int] = None,
        time: Optional[float] = None,
        noise: Optional[float] = None,
    ) -> None: ...
    @property
    def spp(self) -> int: ...
    def describe(self, camera: NativeCamera) -> str: ...

class NativeFilm:
    """A film passes are added to in order (``lumiere.distributed``'s driver)."""

    seconds: float
    def __init__(self, width: int, height: int) -> None: ...
    @property
    def samples(self) -> int: ...
    @property
    def rays(self) -> int: ...
    @property
    def discarded(self) -> int: ...
    def add_pass(self, sample: int, values: bytes, rays: int) -> None: ...
    def relative_error(self) -> Optional[float]: ...
    def image(self) -> bytearray: ...
    def save_checkpoint(self, path: _Path, scene: NativeScene, camera: NativeCamera, options: NativeOptions) -> None: ...
    @staticmethod
    def load_checkpoint(path: _Path, scene: NativeScene, camera: NativeCamera, options: NativeOptions) -> NativeFilm: ...

def render(
    scene: NativeScene,
    camera: NativeCamera,
    options: NativeOptions,
    threads: int,
    aovs: List[str],
    progress: Optional[_Progress] = None,
    stacklevel: int = 1,
) -> Tuple[bytearray, List[bytearray], Dict[str, Any]]:
    """The image and AOVs as float32 RGB bytes (row 0 at the top) and the statistics; its
    warnings go ``stacklevel`` frames up from the caller (1: the caller's line)."""

def render_passes(
    scene: NativeScene,
    camera: NativeCamera,
    options: NativeOptions,
    first: int,
    count: int,
    threads: int,
    progress: Optional[_Progress] = None,
) -> List[Tuple[int, bytearray, int]]:
    """Passes ``first .. first + count``: (sample index, float32 RGB bytes, rays) each."""

def write_image(
    path: _Path, width: int, height: int, pixels: bytes, exposure: float = 0.0, tonemap: str = "aces"
) -> None: ...

def read_input(path: _Path) -> bytes:
    """The bytes of a regular file (FIFOs and devices refused unread), as scenes are read."""

def check_outputs(
    outputs: Sequence[Tuple[str, _Path]], inputs: Sequence[Tuple[str, _Path]], scene: Optional[NativeScene] = None
) -> None:
    """Refuses (name, path) outputs that are one file, an input, or a file ``scene`` read."""
