"""Python's overhead on a ~1 second render: lumiere.render's wall time against the library's own
rendering time (stats["seconds"]) and against `lumiere render` (its --stats-json render_ms and its
wall time), interleaved. Usage: python bench/overhead.py [path/to/lumiere]"""

import json
import statistics
import subprocess
import sys
import tempfile
import time

import lumiere

SIZE, SPP, REPEATS = (512, 384), 4, 7
cli = sys.argv[1] if len(sys.argv) > 1 else "target/release/lumiere"
scene = lumiere.builtin()
lumiere.render(scene, spp=1, size=(64, 48))  # warm up
rows = []
with tempfile.TemporaryDirectory() as tmp:
    for _ in range(REPEATS):
        start = time.perf_counter()
        result = lumiere.render_full(scene, spp=SPP, size=SIZE)
        wall = time.perf_counter() - start
        start = time.perf_counter()
        subprocess.run([cli, "render", "--size", "x".join(map(str, SIZE)), "--spp", str(SPP), "-o", f"{tmp}/x.pfm",
                        "--stats-json", f"{tmp}/s.json"], check=True, capture_output=True)
        cli_wall = time.perf_counter() - start
        cli_render = json.load(open(f"{tmp}/s.json"))["render_ms"] / 1e3
        rows.append((wall, result.stats["seconds"], cli_wall, cli_render))
wall, inner, cli_wall, cli_render = (statistics.median(column) for column in zip(*rows))
print(f"{SIZE[0]}x{SIZE[1]} path {SPP} spp, median of {REPEATS}, interleaved")
print(f"lumiere.render wall {wall:.3f} s; library render time inside it {inner:.3f} s; "
      f"overhead {wall - inner:.4f} s = {100 * (wall - inner) / inner:.2f}%")
print(f"lumiere render (CLI) wall {cli_wall:.3f} s (process start, scene load, BVH, PFM write included); "
      f"its render_ms {cli_render:.3f} s; Python wall / CLI render_ms = {wall / cli_render:.3f}")
