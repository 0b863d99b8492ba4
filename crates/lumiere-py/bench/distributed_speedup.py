"""lumiere.distributed on 1 and 2 worker processes (1-CPU Ray nodes on 127.0.0.1, a head plus
one more node) against single-process renders: wall times, speed-up, per-task overhead, bytes
shipped, the driver's merge cost, and a check that every image has the same bytes.

Usage: python bench/distributed_speedup.py [SPP] [WIDTHxHEIGHT] [TASKS]   (default 64 512x384 16)"""

import os
import sys
import time

os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")  # keep Ray on 127.0.0.1

import numpy as np  # noqa: E402
import ray  # noqa: E402
from ray.cluster_utils import Cluster  # noqa: E402

import lumiere  # noqa: E402
import lumiere.distributed as distributed  # noqa: E402
from lumiere import _lumiere  # noqa: E402

spp = int(sys.argv[1]) if len(sys.argv) > 1 else 64
width, height = (int(v) for v in (sys.argv[2] if len(sys.argv) > 2 else "512x384").split("x"))
tasks = int(sys.argv[3]) if len(sys.argv) > 3 else 16
scene = lumiere.builtin()
size = (width, height)
pixels = width * height

# The driver's cost per pass: adding 12 bytes a pixel to the film, in pass order.
film = _lumiere.NativeFilm(width, height)
values = np.random.default_rng(0).random(pixels * 3, dtype=np.float32).tobytes()
start = time.perf_counter()
for sample in range(16):
    film.add_pass(sample, values, 0)
merge = (time.perf_counter() - start) / 16

results = {}
start = time.perf_counter()
results["local, 1 thread"] = (lumiere.render(scene, spp=spp, size=size, threads=1), time.perf_counter() - start, None)
start = time.perf_counter()
results["local, 2 threads"] = (lumiere.render(scene, spp=spp, size=size, threads=2), time.perf_counter() - start, None)
for workers in (1, 2):
    cluster = Cluster(initialize_head=True,
                      head_node_args={"num_cpus": 1, "include_dashboard": False, "node_ip_address": "127.0.0.1"})
    for _ in range(workers - 1):
        cluster.add_node(num_cpus=1, node_ip_address="127.0.0.1")
    ray.init(address=cluster.address, logging_level="warning")
    # Warm-up: worker processes started, the scene loaded in each.
    distributed.render(scene, spp=2 * workers, size=(16, 12), address=cluster.address, tasks=2 * workers)
    start = time.perf_counter()
    result = distributed.render_full(scene, spp=spp, size=size, address=cluster.address, tasks=tasks)
    wall = time.perf_counter() - start
    results[f"Ray, {workers} worker process{'es' if workers > 1 else ''}"] = (result.image, wall, result.stats)
    ray.shutdown()
    cluster.shutdown()

reference = results["local, 1 thread"][0].view(np.uint32)
one_worker = results["Ray, 1 worker process"][1]
print(f"{width}x{height} path, {spp} spp, {tasks} tasks of {spp / tasks:g} passes; "
      f"{12 * pixels / 1e6:.2f} MB shipped per pass, {12 * pixels * spp / 1e6:.0f} MB in all")
print(f"load average before: {os.getloadavg()[0]:.2f} (other processes on the machine; 2 cores)")
print("| run | wall s | speed-up vs 1 worker | tasks' wall s | tasks' CPU s | overhead per task s | same bytes |")
print("|---|---|---|---|---|---|---|")
for name, (image, wall, stats) in results.items():
    same = np.array_equal(image.view(np.uint32), reference)
    if stats is None:
        print(f"| {name} | {wall:.2f} | {one_worker / wall:.2f} | | | | {same} |")
        continue
    workers = 2 if "2 worker" in name else 1
    busy = sum(t["seconds"] for t in stats["tasks"])
    cpu = sum(t["cpu_seconds"] for t in stats["tasks"])
    # What the workers' time did not go to rendering: scheduling, shipping, merging, the tail.
    overhead = (workers * wall - busy) / len(stats["tasks"])
    print(f"| {name} | {wall:.2f} | {one_worker / wall:.2f} | {busy:.2f} | {cpu:.2f} | {overhead:.3f} | {same} |")
print(f"driver merge: {1e3 * merge:.1f} ms per pass ({12 * pixels / merge / 1e9:.2f} GB/s)")
