#!/usr/bin/env python3
"""Compare lumiere's BVH traversal with Embree (through embreex) on the same rays.

Runs `lumiere bench-bvh --export-rays OUT --json OUT/lumiere.json`, then traces every exported ray
set with embreex (closest hit with rtcIntersect1, occlusion with rtcOccluded1) on as many worker
processes as lumiere had threads, and prints a Markdown table with both throughputs, their ratio and
how often Embree's answers agree with lumiere's. See bench/README.md.

Requires Python 3.11+, numpy and embreex (`pip install -r bench/requirements.txt`).
"""

from __future__ import annotations

import argparse
import datetime
import json
import multiprocessing as mp
import os
import platform
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

RAY_SETS = [("primary", "closest"), ("shadow", "occluded"), ("diffuse", "occluded"), ("diffuse", "closest")]
DEFAULT_SCENES = "cornell,bunny,bunny-1m,staircase"


# ---------------------------------------------------------------------------------------------
# Binary files written by `lumiere bench-bvh --export-rays` (little-endian).


def _header(path: Path, magic: bytes) -> int:
    with open(path, "rb") as f:
        head = f.read(16)
    if len(head) != 16 or head[:4] != magic:
        raise SystemExit(f"{path}: not a {magic.decode()} file")
    version = int.from_bytes(head[4:8], "little")
    if version != 1:
        raise SystemExit(f"{path}: unsupported version {version}")
    return int.from_bytes(head[8:16], "little")


def load_mesh(path: Path) -> np.ndarray:
    """mesh.bin -> (T, 3, 3) float32, triangle ids in lumiere's order."""
    count = _header(path, b"LMSH")
    tris = np.fromfile(path, dtype="<f4", count=count * 9, offset=16)
    if tris.size != count * 9:
        raise SystemExit(f"{path}: truncated")
    return tris.astype(np.float32, copy=False).reshape(count, 3, 3)


def ray_count(path: Path) -> int:
    return _header(path, b"LRAY")


def load_rays(path: Path, start: int = 0, stop: int | None = None) -> np.ndarray:
    """Rays [start, stop) of a .rays file -> (n, 7) float32 (origin, direction, tmax)."""
    count = _header(path, b"LRAY")
    stop = count if stop is None else min(stop, count)
    n = max(stop - start, 0)
    rays = np.fromfile(path, dtype="<f4", count=n * 7, offset=16 + start * 28)
    if rays.size != n * 7:
        raise SystemExit(f"{path}: truncated")
    return rays.astype(np.float32, copy=False).reshape(n, 7)


def load_expect(path: Path, query: str, count: int) -> np.ndarray:
    """lumiere's answers: triangle id (-1 miss) for closest, bool for occluded."""
    if query == "closest":
        ids = np.fromfile(path, dtype="<i4")
    else:
        ids = np.fromfile(path, dtype=np.uint8).astype(bool)
    if ids.size != count:
        raise SystemExit(f"{path}: {ids.size} answers for {count} rays")
    return ids


# ---------------------------------------------------------------------------------------------
# Embree workers: one process per thread (embreex holds the GIL while tracing).


def _worker(mesh_path: str, conn, barrier) -> None:
    """Builds its own Embree scene, then traces the jobs the parent sends until told to stop."""
    from embreex import mesh_construction, rtcore_scene

    tris = load_mesh(Path(mesh_path))
    scene = rtcore_scene.EmbreeScene()
    mesh_construction.TriangleMesh(scene, tris)
    del tris
    # embreex commits (builds the BVH) lazily on the first run(): do it now, outside the timings.
    one = np.zeros((1, 3), np.float32)
    scene.run(one, np.array([[0, 0, 1]], np.float32), query="INTERSECT")
    conn.send("ready")
    while True:
        job = conn.recv()
        if job is None:
            break
        rays_path, query, start, stop, repeats = job
        rays = load_rays(Path(rays_path), start, stop)
        origins = np.ascontiguousarray(rays[:, 0:3])
        dirs = np.ascontiguousarray(rays[:, 3:6])
        # tmax goes to Embree's tfar (in units of the unnormalised direction, like lumiere's tmax);
        # embreex sets tnear = 0. run() does not write into `dists` unless output= is given.
        tmax = np.ascontiguousarray(rays[:, 6])
        del rays
        embree_query = "INTERSECT" if query == "closest" else "OCCLUDED"
        times, answers = [], None
        for _ in range(repeats):
            barrier.wait(timeout=600)
            t0 = time.perf_counter()  # CLOCK_MONOTONIC: comparable between processes
            ids = scene.run(origins, dirs, dists=tmax, query=embree_query)
            t1 = time.perf_counter()
            times.append((t0, t1))
            if answers is None:
                answers = ids
        conn.send((times, answers))


class EmbreePool:
    """`n` worker processes, each with its own Embree scene built from mesh.bin."""

    def __init__(self, mesh_path: Path, n: int):
        ctx = mp.get_context("spawn")  # no Embree/TBB state shared through fork
        self.barrier = ctx.Barrier(n)
        self.conns, self.procs = [], []
        for _ in range(n):
            parent, child = ctx.Pipe()
            p = ctx.Process(target=_worker, args=(str(mesh_path), child, self.barrier), daemon=True)
            p.start()
            child.close()
            self.conns.append(parent)
            self.procs.append(p)
        for c in self.conns:
            if c.recv() != "ready":
                raise RuntimeError("embree worker failed to start")

    def trace(self, rays_path: Path, query: str, count: int, repeats: int) -> tuple[float, np.ndarray]:
        """Median wall time (first worker start to last worker done) and the answers of one run."""
        n = len(self.conns)
        bounds = [count * i // n for i in range(n + 1)]
        for i, c in enumerate(self.conns):
            c.send((str(rays_path), query, bounds[i], bounds[i + 1], repeats))
        results = [c.recv() for c in self.conns]
        walls = sorted(
            max(r[0][k][1] for r in results) - min(r[0][k][0] for r in results) for k in range(repeats)
        )
        ids = np.concatenate([r[1] for r in results]) if results else np.empty(0, np.int32)
        return walls[len(walls) // 2], ids

    def close(self) -> None:
        for c in self.conns:
            c.send(None)
        for p in self.procs:
            p.join(timeout=30)
            if p.is_alive():
                p.terminate()


# ---------------------------------------------------------------------------------------------


def machine() -> str:
    model = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        model = platform.processor() or model
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return f"{model}, {os.cpu_count()} logical cores ({usable} usable), {platform.system()} {platform.release()}"


def versions() -> str:
    from importlib.metadata import PackageNotFoundError, version

    parts = [f"Python {platform.python_version()}"]
    for pkg in ("embreex", "numpy"):
        try:
            parts.append(f"{pkg} {version(pkg)}")
        except PackageNotFoundError:
            parts.append(f"{pkg} ?")
    try:
        # The repository's commit, wherever the script is run from.
        repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        rev = subprocess.run(["git", "-C", repo, "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True)
        dirty = subprocess.run(["git", "-C", repo, "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True)
        parts.append(f"lumiere {rev.stdout.strip()}{' (modified)' if dirty.stdout.strip() else ''}")
    except (OSError, subprocess.CalledProcessError):
        pass
    return ", ".join(parts)


def compare(query: str, ours: np.ndarray, embree: np.ndarray) -> tuple[int, str]:
    """Number of differing rays and a short breakdown."""
    if query == "closest":
        embree = embree.astype(np.int64)
        ours = ours.astype(np.int64)
        embree[embree < 0] = -1
        differ = ours != embree
        only_ours = int(np.count_nonzero(differ & (embree < 0)))
        only_embree = int(np.count_nonzero(differ & (ours < 0)))
        other = int(np.count_nonzero(differ)) - only_ours - only_embree
        detail = f"{only_ours} hit by lumiere only, {only_embree} by Embree only, {other} on different triangles"
    else:
        occluded = embree != -1  # embreex returns 0 for occluded, -1 for unoccluded
        differ = ours != occluded
        only_ours = int(np.count_nonzero(differ & ours))
        detail = f"{only_ours} occluded for lumiere only, {int(np.count_nonzero(differ)) - only_ours} for Embree only"
    return int(np.count_nonzero(differ)), detail


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lumiere", default="./target/release/lumiere", help="lumiere binary (default %(default)s)")
    ap.add_argument("--scenes", default=DEFAULT_SCENES, help="comma-separated (default %(default)s)")
    ap.add_argument("--threads", default="1,2", help="comma-separated thread counts (default %(default)s)")
    ap.add_argument("--repeats", type=int, default=5, help="timed runs per measurement, median kept (default %(default)s)")
    ap.add_argument("--out", help="folder for lumiere.json and the exported rays (default: a new temporary folder)")
    ap.add_argument("--skip-lumiere", action="store_true", help="reuse --out from an earlier run (needs lumiere.json)")
    ap.add_argument("--scenes-dir", help="passed to lumiere bench-bvh --scenes-dir (default: lumiere's)")
    args = ap.parse_args()

    scenes = [s.strip() for s in args.scenes.split(",") if s.strip()]
    threads = [int(t) for t in args.threads.split(",") if t.strip()]
    if args.skip_lumiere and not args.out:
        ap.error("--skip-lumiere needs --out")
    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="lumiere-embree-"))
    out.mkdir(parents=True, exist_ok=True)
    json_path = out / "lumiere.json"

    command = shlex.join(["python3", *sys.argv])
    started = datetime.datetime.now().astimezone()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")

    if not args.skip_lumiere:
        cmd = [args.lumiere, "bench-bvh", "--scenes", ",".join(scenes), "--threads", ",".join(map(str, threads)),
               "--repeats", str(args.repeats), "--json", str(json_path), "--export-rays", str(out)]
        if args.scenes_dir:
            cmd += ["--scenes-dir", args.scenes_dir]
        print(f"running: {shlex.join(cmd)}", file=sys.stderr, flush=True)
        # lumiere's progress goes to our stderr; its Markdown tables are kept in OUT/lumiere.md.
        done = subprocess.run(cmd, stdout=subprocess.PIPE, text=True)
        (out / "lumiere.md").write_text(done.stdout)
        if done.returncode != 0:
            sys.stdout.write(done.stdout)
            print(f"lumiere exited with status {done.returncode}", file=sys.stderr)
            return 1
        print(f"lumiere's own tables: {out / 'lumiere.md'}", file=sys.stderr, flush=True)
    if not json_path.exists():
        print(f"{json_path} not found", file=sys.stderr)
        return 1
    records = json.loads(json_path.read_text())
    lumiere_mrays = {
        (r["scene"], r["kind"], r["query"], r["threads"]): r["mrays_per_s"] for r in records if r.get("what") == "trace"
    }

    rows, notes = [], []
    for scene in scenes:
        folder = out / scene
        mesh_path = folder / "mesh.bin"
        if not mesh_path.exists():
            print(f"{mesh_path} not found (was lumiere run with --export-rays?)", file=sys.stderr)
            return 1
        tris = load_mesh(mesh_path)
        degenerate = int(np.count_nonzero(
            np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1) == 0))
        triangles = len(tris)
        del tris
        if degenerate:
            notes.append(f"{scene}: {degenerate} of {triangles} triangles have zero area")
        answers = {}
        for n in threads:
            t = time.perf_counter()
            pool = EmbreePool(mesh_path, n)
            print(f"{scene}: {triangles} triangles, {n} Embree worker(s) ready in {time.perf_counter() - t:.1f} s",
                  file=sys.stderr, flush=True)
            try:
                for kind, query in RAY_SETS:
                    stem = f"{kind}-{query}"
                    rays_path = folder / f"{stem}.rays"
                    count = ray_count(rays_path)
                    seconds, ids = pool.trace(rays_path, query, count, args.repeats)
                    embree = count / seconds / 1e6
                    ours = lumiere_mrays.get((scene, kind, query, n))
                    if stem not in answers:  # same rays for every thread count: compare once
                        expect = load_expect(folder / f"{stem}.expect", query, count)
                        answers[stem] = compare(query, expect, ids)
                        del expect
                        if answers[stem][0]:
                            notes.append(f"{scene} {kind} {query}: {answers[stem][0]} of {count} rays differ "
                                         f"({answers[stem][1]})")
                    differ = answers[stem][0]
                    agree = 100.0 * (count - differ) / count if count else 100.0
                    agree_text = f"{agree:.3f}" if differ == 0 or agree < 99.9995 else ">99.999"
                    rows.append(
                        f"| {scene} | {kind} {query} | {n} | {count} | "
                        f"{'n/a' if ours is None else f'{ours:.1f}'} | {embree:.1f} | "
                        f"{'n/a' if ours is None else f'{ours / embree:.2f}'} | {agree_text} | {differ} |")
                    print(f"  {kind} {query}, {n} worker(s): {seconds * 1e3:.1f} ms, {embree:.1f} Mrays/s",
                          file=sys.stderr, flush=True)
                    del ids
            finally:
                pool.close()

    print()
    print(f"Command: `{command}`  ")
    print(f"Machine: {machine()}, 1-min load average {load:.2f} at start (timings assume an idle machine)  ")
    print(f"Software: {versions()}  ")
    print(f"Date: {started.strftime('%Y-%m-%d %H:%M %Z')}, median of {args.repeats} runs; "
          f"Embree: embreex single-ray API, one process per thread, contiguous share of the rays each")
    print()
    print("| scene | rays | threads | count | lumiere Mrays/s | Embree Mrays/s | ratio (lumiere/Embree) "
          "| agreement with lumiere (%) | rays differing |")
    print("|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        print(row)
    if notes:
        print()
        for note in notes:
            print(f"- {note}")
    print(f"\n(exported rays and lumiere.json in {out})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
