"""Shared fixtures: the `lumiere` binary to compare against, and PFM reading."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]

# Ray, where a test starts it, stays on the loopback address: without this it advertises the
# machine's network address even for a cluster on 127.0.0.1.
os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")


def _cli_path() -> pathlib.Path:
    if "LUMIERE_CLI" in os.environ:
        return pathlib.Path(os.environ["LUMIERE_CLI"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "release" / "lumiere"


@pytest.fixture(scope="session")
def cli():
    """Runs `lumiere ARGS...`; returns the completed process. Build it with `cargo build --release`."""
    path = _cli_path()
    if not path.exists():
        pytest.fail(f"{path} not found: run `cargo build --release` first (or set LUMIERE_CLI)")

    def run(*args, check=True):
        result = subprocess.run([str(path), *map(str, args)], capture_output=True, text=True, timeout=300)
        if check and result.returncode != 0:
            raise AssertionError(f"lumiere {' '.join(map(str, args))} failed: {result.stderr}")
        return result

    return run


def optional(module: str, install: str):
    """Imports an optional dependency, or skips the test without it; CI sets
    LUMIERE_REQUIRE_EXTRAS=1 so that a missing one fails instead of skipping."""
    if os.environ.get("LUMIERE_REQUIRE_EXTRAS") == "1":
        return __import__(module)
    return pytest.importorskip(module, reason=f"{module} is not installed: {install}")


def read_pfm(path) -> np.ndarray:
    """A PFM file as lumiere writes it (little-endian RGB, rows bottom to top) as (h, w, 3), top row first."""
    data = pathlib.Path(path).read_bytes()
    magic, size, scale, pixels = data.split(b"\n", 3)
    assert magic == b"PF" and float(scale) < 0, "a little-endian RGB PFM"
    width, height = map(int, size.split())
    image = np.frombuffer(pixels, dtype="<f4").reshape(height, width, 3)
    return image[::-1]
