#!/usr/bin/env python3
"""Compare lumiere's path tracer with Mitsuba 3 at equal error on the gKit Cornell box.

Builds the Cornell box embedded in lumiere as a Mitsuba scene (one shape per material, diffuse BSDFs
of the MTL's Kd, an area emitter of its Ke, the same vertex normals), derives a look-at camera from
lumiere's orbiter and checks it (lumiere both ways, and Mitsuba's albedo against lumiere's
materials), renders a converged Mitsuba reference once (cached), then renders both at equal spp with
several seeds and prints time, RMSE, bias and efficiency = 1 / (time x MSE) as a Markdown table.
See bench/README.md.

Requires Python 3.11+, numpy and mitsuba (`pip install -r bench/requirements-mitsuba.txt`), and an
LLVM >= 16 shared library for Mitsuba's `llvm_ad_rgb` variant (DRJIT_LIBLLVM_PATH).
"""

from __future__ import annotations

import argparse
import datetime
import glob
import hashlib
import json
import math
import os
import platform
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
CORNELL = REPO / "crates" / "lumiere" / "assets" / "cornell"
VARIANT = "llvm_ad_rgb"
# Samples (pixels x spp) per Mitsuba render call for the reference: bounds the wavefront's memory.
REF_LANES_PER_PASS = 1 << 24


# ---------------------------------------------------------------------------------------------
# The scene: the OBJ split by material, as lumiere reads it.


def read_mtl(path: Path) -> dict[str, dict[str, np.ndarray]]:
    materials: dict[str, dict[str, np.ndarray]] = {}
    current = None
    for line in path.read_text().splitlines():
        tokens = line.split()
        if not tokens or tokens[0].startswith("#"):
            continue
        if tokens[0] == "newmtl":
            current = materials.setdefault(tokens[1], {})
        elif current is not None and tokens[0] in ("Kd", "Ke"):
            current[tokens[0]] = np.array([float(t) for t in tokens[1:4]])
    return materials


def read_obj(path: Path):
    """Positions, normals and, per material in file order, triangles as ((v0, v1, v2), (n0, n1, n2))
    with 0-based indices. Polygons are split as lumiere (and gKit) split them: fans (a,b,c), (a,c,d)."""
    positions, normals, groups = [], [], {}
    material = None
    for line in path.read_text().splitlines():
        tokens = line.split()
        if not tokens:
            continue
        if tokens[0] == "v":
            positions.append([float(t) for t in tokens[1:4]])
        elif tokens[0] == "vn":
            normals.append([float(t) for t in tokens[1:4]])
        elif tokens[0] == "usemtl":
            material = tokens[1]
        elif tokens[0] == "f":
            corners = []
            for corner in tokens[1:]:
                parts = corner.split("/")
                v = int(parts[0])
                n = int(parts[2]) if len(parts) > 2 and parts[2] else 0
                v = v - 1 if v > 0 else len(positions) + v
                n = (n - 1 if n > 0 else len(normals) + n) if n else -1
                corners.append((v, n))
            for i in range(1, len(corners) - 1):
                tri = (corners[0], corners[i], corners[i + 1])
                groups.setdefault(material, []).append((tuple(c[0] for c in tri), tuple(c[1] for c in tri)))
    return np.array(positions), np.array(normals), groups


def write_scene_files(folder: Path, log) -> list[dict]:
    """Writes one OBJ per material under `folder`; returns [{name, path, kd, ke, flip}]."""
    positions, normals, groups = read_obj(CORNELL / "cornell.obj")
    mtl = read_mtl(CORNELL / "cornell.mtl")
    lo, hi = positions.min(axis=0), positions.max(axis=0)
    centre = (lo + hi) / 2
    shapes = []
    for name, tris in groups.items():
        mat = mtl.get(name, {})
        kd = mat.get("Kd", np.full(3, 0.8))
        ke = mat.get("Ke", np.zeros(3))
        lines = [f"# {name} from cornell.obj: triangles (lumiere's fan split), vertex normals kept"]
        worst = 0.0
        flip = False
        for k, (vs, ns) in enumerate(tris):
            p = positions[list(vs)]
            ng = np.cross(p[1] - p[0], p[2] - p[0])
            ng /= np.linalg.norm(ng)
            for j in range(3):
                lines.append("v " + " ".join(f"{x:.9g}" for x in p[j]))
            has_n = all(n >= 0 for n in ns)
            if has_n:
                for j in range(3):
                    n = normals[ns[j]]
                    lines.append("vn " + " ".join(f"{x:.9g}" for x in n))
                    worst = max(worst, math.degrees(math.acos(max(-1.0, min(1.0, float(ng @ n) / np.linalg.norm(n))))))
                lines.append(f"f {3*k+1}//{3*k+1} {3*k+2}//{3*k+2} {3*k+3}//{3*k+3}")
            else:
                lines.append(f"f {3*k+1} {3*k+2} {3*k+3}")
            if ke.max() > 0:
                # Mitsuba's area emitters, like lumiere's, emit on the side of the winding's normal.
                # The box's light must face into the box.
                inward = float(ng @ (centre - p.mean(axis=0))) > 0
                flip = flip or not inward
                if not inward:
                    log(f"note: light triangle {k} of {name} faces away from the box: flip_normals set")
        file = folder / f"{name}.obj"
        file.write_text("\n".join(lines) + "\n")
        log(f"  {name}: {len(tris)} triangles, Kd {kd.tolist()}, Ke {ke.tolist()}, "
            f"largest angle vn vs face normal {worst:.3f} deg")
        shapes.append({"name": name, "path": file, "kd": kd, "ke": ke, "flip": flip})
    return shapes


# ---------------------------------------------------------------------------------------------
# The camera: gKit's orbiter (crates/lumiere/src/scene/camera.rs) as a look-at.


def read_orbiter(path: Path) -> dict[str, list[float]]:
    fields = {}
    for line in path.read_text().splitlines():
        tokens = line.split()
        if tokens and tokens[0] in "cprsf":
            fields[tokens[0]] = [float(t) for t in tokens[1:]]
    return fields


def _translation(t) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = t
    return m


def _rotation_x(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def _rotation_y(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]])


def orbiter_look_at(orbiter: dict[str, list[float]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eye, target and up of gKit's `Orbiter::view()`:
    view = T(-pan.x, -pan.y, -size) * Rx(r.x) * Ry(r.y) * T(-center). The camera sits at the origin
    of view space looking down -z with +y up, so in the world it is at inverse(view) * (0,0,0,1),
    looks along inverse(view) * (0,0,-1,0), with up inverse(view) * (0,1,0,0). gKit's projection is
    the symmetric OpenGL perspective of vertical fov 45 and aspect width/height, so the look-at with
    `--fov 45` spans the same rays (the orbiter's start on its near plane, 0.1 in front of the eye
    here; nothing of the scene is that close)."""
    c, p, r, s = orbiter["c"], orbiter["p"], orbiter["r"], orbiter["s"]
    view = _translation([-p[0], -p[1], -s[0]]) @ _rotation_x(r[0]) @ _rotation_y(r[1]) @ _translation([-x for x in c])
    inv = np.linalg.inv(view)
    eye = (inv @ [0, 0, 0, 1])[:3]
    forward = (inv @ [0, 0, -1, 0])[:3]
    up = (inv @ [0, 1, 0, 0])[:3]
    # Any point along the axis will do; at the orbiter's distance it lands near the scene's centre.
    target = eye + forward * s[0]
    return eye, target, up


def edge_pixels(img: np.ndarray) -> np.ndarray:
    """Pixels whose 3x3 neighbourhood holds another colour (or leaves the image): where the pixel's
    footprint may cross an edge that its centre does not see."""
    # Outside the image counts as another colour: an edge may cross a border pixel beyond its centre.
    padded = np.pad(img, ((1, 1), (1, 1), (0, 0)), constant_values=np.nan)
    h, w = img.shape[:2]
    edge = np.zeros((h, w), bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            edge |= np.any(padded[dy:dy + h, dx:dx + w] != img, axis=-1)
    return edge


def vec(v) -> str:
    return ",".join(f"{x:.9g}" for x in v)


# ---------------------------------------------------------------------------------------------
# Images.


def read_exr(path: Path) -> np.ndarray:
    import mitsuba as mi

    img = np.array(mi.Bitmap(str(path)), dtype=np.float64)
    return img[..., :3] if img.ndim == 3 else img


def write_exr(path: Path, img: np.ndarray) -> None:
    import mitsuba as mi

    mi.Bitmap(np.ascontiguousarray(img, dtype=np.float32), mi.Bitmap.PixelFormat.RGB).write(str(path))


# ---------------------------------------------------------------------------------------------
# Renderers.


def run_lumiere(args, camera: list[str], out: Path, extra: list[str]) -> tuple[np.ndarray, dict, float, float]:
    """The image, lumiere's --stats-json, the process's wall time and its CPU time (all threads)."""
    stats = out.with_suffix(".json")
    cmd = [args.lumiere, "render", *extra, "--size", args.size, "--threads", str(args.threads),
           *camera, "-o", str(out), "--stats-json", str(stats)]
    t = time.perf_counter()
    before = os.times()
    done = subprocess.run(cmd, capture_output=True, text=True)
    after = os.times()
    wall = time.perf_counter() - t
    cpu = (after.children_user + after.children_system) - (before.children_user + before.children_system)
    if done.returncode != 0:
        raise SystemExit(f"{shlex.join(cmd)} failed ({done.returncode}):\n{done.stderr}")
    return read_exr(out), json.loads(stats.read_text()), wall, cpu


def mitsuba_scene_dict(shapes, eye, target, up, width, height, integrator: dict, sampler: str = "independent") -> dict:
    import mitsuba as mi

    scene = {
        "type": "scene",
        "integrator": integrator,
        "sensor": {
            "type": "perspective",
            "fov": 45.0,
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=eye.tolist(), target=target.tolist(), up=up.tolist()),
            "sampler": {"type": sampler, "sample_count": 1},
            "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"},
                     "pixel_format": "rgb", "component_format": "float32"},
        },
    }
    for i, shape in enumerate(shapes):
        entry = {
            "type": "obj",
            "filename": str(shape["path"]),
            "face_normals": False,  # the file's vertex normals are the shading normals, as in lumiere
            # lumiere shades both sides of every triangle; Mitsuba's diffuse is one-sided.
            "bsdf": {"type": "twosided", "material": {"type": "diffuse",
                                                      "reflectance": {"type": "rgb", "value": shape["kd"].tolist()}}},
        }
        if shape["ke"].max() > 0:
            entry["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": shape["ke"].tolist()}}
            if shape["flip"]:
                entry["flip_normals"] = True
        scene[f"shape_{i:02d}"] = entry
    return scene


def mitsuba_render(scene, spp: int, seed: int) -> tuple[np.ndarray, float, float]:
    """One render of `spp` samples per pixel: the image, the seconds from the call to the evaluated
    image, and the CPU time of the process (all Dr.Jit threads) over the same span."""
    import drjit as dr
    import mitsuba as mi

    t, c = time.perf_counter(), time.process_time()
    img = mi.render(scene, spp=spp, seed=seed)
    dr.eval(img)
    dr.sync_thread()
    seconds, cpu = time.perf_counter() - t, time.process_time() - c
    return np.array(img, dtype=np.float64)[..., :3], seconds, cpu


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


def lumiere_commit(binary: str) -> str:
    """The work tree's commit for its own build; for another binary its path beside it, since a
    binary cannot say which commit it was built from."""
    try:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True,
                             cwd=REPO)
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], capture_output=True,
                               text=True, cwd=REPO)
        commit = rev.stdout.strip() + (" (modified)" if dirty.stdout.strip() else "")
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    if Path(binary).resolve() != (REPO / "target" / "release" / "lumiere").resolve():
        return f"binary {binary} (not this work tree's build, which is at {commit})"
    return commit


def find_libllvm() -> str | None:
    for pattern in ("/usr/lib/x86_64-linux-gnu/libLLVM-*.so", "/usr/lib/aarch64-linux-gnu/libLLVM-*.so",
                    "/usr/lib/llvm-*/lib/libLLVM*.so"):
        found = sorted(glob.glob(pattern), key=lambda p: [int(x) for x in "".join(
            ch if ch.isdigit() else " " for ch in Path(p).name).split()] or [0])
        if found:
            return found[-1]
    return None


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lumiere", default=str(REPO / "target" / "release" / "lumiere"),
                    help="lumiere binary (default ./target/release/lumiere)")
    ap.add_argument("--size", default="1024x768", help="WIDTHxHEIGHT (default %(default)s)")
    ap.add_argument("--spp", type=int, default=64,
                    help="samples per pixel of the compared renders (default %(default)s)")
    ap.add_argument("--ref-spp", type=int, default=4096,
                    help="samples per pixel of Mitsuba's reference (default %(default)s)")
    ap.add_argument("--max-depth", type=int, default=8, help="path length, Mitsuba's count (default %(default)s)")
    ap.add_argument("--repeats", type=int, default=3, help="renders per renderer, seeds 1..N (default %(default)s)")
    ap.add_argument("--threads", type=int, default=2, help="threads for both renderers (default %(default)s)")
    ap.add_argument("--lumiere-sampler", default="sobol",
                    help="lumiere's --sampler for the timed renders, comma-separated for several "
                         "(independent, sobol; default %(default)s, its default for path)")
    ap.add_argument("--mitsuba-sampler", default="independent,multijitter",
                    help="Mitsuba samplers for the timed renders, comma-separated (independent, stratified, "
                         "multijitter, orthogonal, ldsampler; default %(default)s: its default and its best "
                         "at 64 spp on this scene)")
    ap.add_argument("--camera", choices=["orbiter", "look-at"], default="orbiter",
                    help="lumiere's camera for the timed renders (Mitsuba always uses the look-at; "
                         "default %(default)s)")
    ap.add_argument("--cache", default=os.path.join(tempfile.gettempdir(), "lumiere-mitsuba-cache"),
                    help="folder of the cached reference EXR (default %(default)s)")
    ap.add_argument("--out", help="folder for the scene files and images (default: a new temporary folder)")
    args = ap.parse_args()

    def log(msg: str) -> None:
        print(msg, file=sys.stderr, flush=True)

    width, height = (int(x) for x in args.size.lower().split("x"))
    lumiere_samplers = [x.strip() for x in args.lumiere_sampler.split(",") if x.strip()]
    mitsuba_samplers = [x.strip() for x in args.mitsuba_sampler.split(",") if x.strip()]
    if not lumiere_samplers or not mitsuba_samplers:
        ap.error("--lumiere-sampler and --mitsuba-sampler need at least one sampler each")
    if not Path(args.lumiere).exists():
        ap.error(f"{args.lumiere} not found: run `cargo build --release` first")
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        lib = find_libllvm()
        if lib:
            os.environ["DRJIT_LIBLLVM_PATH"] = lib
    import drjit as dr
    import mitsuba as mi

    try:
        mi.set_variant(VARIANT)
    except Exception as e:  # noqa: BLE001 - the message says what is missing
        raise SystemExit(f"mitsuba variant {VARIANT} failed ({e}); install an LLVM >= 16 shared library and set "
                         f"DRJIT_LIBLLVM_PATH (see bench/README.md)")
    dr.set_thread_count(args.threads)  # the calling thread counts as one of them

    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="lumiere-mitsuba-"))
    out.mkdir(parents=True, exist_ok=True)
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    command = shlex.join(["python3", *sys.argv])
    started = datetime.datetime.now().astimezone()
    load = os.getloadavg()[0]

    # --- Scene --------------------------------------------------------------------------------
    log(f"scene: {CORNELL / 'cornell.obj'} split by material into {out}")
    shapes = write_scene_files(out, log)

    # --- Camera -------------------------------------------------------------------------------
    orbiter_file = CORNELL / "cornell_orbiter.txt"
    eye, target, up = orbiter_look_at(read_orbiter(orbiter_file))
    look_at = ["--eye", vec(eye), "--target", vec(target), "--up", vec(up), "--fov", "45"]
    orbiter = ["--orbiter", str(orbiter_file)]
    log(f"camera: orbiter {orbiter_file.name} = look-at eye {vec(eye)} target {vec(target)} up {vec(up)}, fov 45")
    checks = []
    a, first_stats, *_ = run_lumiere(args, orbiter, out / "materials-orbiter.exr", ["--mode", "materials", "--spp", "1"])
    # The binary's own commit, from its statistics (binaries before it was there: the work tree's).
    commit = first_stats.get("commit") or lumiere_commit(args.lumiere)
    b, *_ = run_lumiere(args, look_at, out / "materials-lookat.exr", ["--mode", "materials", "--spp", "1"])
    differ = float(np.mean(np.any(np.abs(a - b) > 1e-6, axis=-1)))
    checks.append(f"lumiere --mode materials, --orbiter vs the look-at: {differ:.4%} of pixels differ")
    log(checks[-1])
    # Mitsuba's camera against lumiere's: the albedo AOV (Kd of what the pixel sees), averaged over
    # the pixel, against lumiere's Kd at the pixel centre; only pixels across an edge may differ.
    albedo_scene = mi.load_dict(mitsuba_scene_dict(shapes, eye, target, up, width, height,
                                                   {"type": "aov", "aovs": "albedo:albedo"}))
    albedo, *_ = mitsuba_render(albedo_scene, 16, 0)
    del albedo_scene
    mask = np.any(np.abs(albedo[..., :3] - a) > 1e-3, axis=-1)
    differ_mi = float(np.mean(mask))
    inside = int(np.count_nonzero(mask & ~edge_pixels(a)))
    checks.append(f"Mitsuba albedo (16 spp) vs lumiere materials (pixel centres): {differ_mi:.4%} of pixels differ, "
                  f"{inside} of them away from an edge of lumiere's image")
    log(checks[-1])
    if differ > 0.01 or differ_mi > 0.05 or inside > 0.001 * mask.size:
        log("camera check FAILED: the cameras do not agree")
        return 1

    integrator = {"type": "path", "max_depth": args.max_depth, "rr_depth": 5, "hide_emitters": False}
    # The reference is always rendered with the independent sampler (unbiased, and the one whose
    # passes' spread estimates its noise without the correlations of a stratified pattern).
    scene = mi.load_dict(mitsuba_scene_dict(shapes, eye, target, up, width, height, integrator))
    timed_scenes = {name: mi.load_dict(mitsuba_scene_dict(shapes, eye, target, up, width, height, integrator, name))
                    for name in mitsuba_samplers}

    # --- Reference ----------------------------------------------------------------------------
    # Keyed by everything the reference depends on besides the names above (the scene's files and
    # materials, the camera, the integrator's settings), so that no change reuses a stale one.
    key = hashlib.sha256(repr(([(s["kd"].tolist(), s["ke"].tolist(), s["flip"]) for s in shapes],
                               eye.tolist(), target.tolist(), up.tolist(), integrator)).encode())
    for shape in shapes:
        key.update(Path(shape["path"]).read_bytes())
    ref_path = cache / (f"mitsuba-{mi.__version__}-cornell-{width}x{height}-d{args.max_depth}-{args.ref_spp}spp-"
                        f"{key.hexdigest()[:12]}.exr")
    meta_path = ref_path.with_suffix(".json")
    if ref_path.exists() and meta_path.exists():
        ref = read_exr(ref_path)
        meta = json.loads(meta_path.read_text())
        log(f"reference: {ref_path} (cached)")
    else:
        # At least 16 passes, whose spread estimates the reference's own noise.
        per_pass = max(1, min(args.ref_spp // 16, REF_LANES_PER_PASS // (width * height)))
        while args.ref_spp % per_pass:
            per_pass -= 1
        passes = args.ref_spp // per_pass
        log(f"reference: {args.ref_spp} spp in {passes} passes of {per_pass} (seeds 1000000+), "
            f"{args.threads} threads...")
        total = np.zeros((height, width, 3))
        total_sq = np.zeros((height, width, 3))
        t = time.perf_counter()
        for k in range(passes):
            img, *_ = mitsuba_render(scene, per_pass, 1_000_000 + k)
            total += img
            total_sq += img * img
            if k % max(1, passes // 10) == 0:
                log(f"  pass {k + 1}/{passes}, {time.perf_counter() - t:.0f} s")
        ref = total / passes
        # Variance of the reference (the mean of the passes) per pixel, from the passes' spread: what
        # it adds to every MSE measured against it.
        noise = float(np.mean((total_sq / passes - ref * ref) * passes / max(passes - 1, 1) / passes))
        meta = {"spp": args.ref_spp, "passes": passes, "seconds": time.perf_counter() - t, "noise_mse": noise,
                "mitsuba": mi.__version__, "max_depth": args.max_depth, "size": [width, height]}
        write_exr(ref_path, ref)
        meta_path.write_text(json.dumps(meta, indent=2) + "\n")
        log(f"reference written: {ref_path} ({meta['seconds']:.0f} s)")
    ref_mean = float(ref.mean())

    # --- Equal spp ----------------------------------------------------------------------------
    lumiere_camera = orbiter if args.camera == "orbiter" else look_at
    warm = {}
    actual_spp = {}
    for name, timed in timed_scenes.items():
        log(f"Mitsuba warm-up render, {name} sampler ({args.spp} spp, JIT compilation)...")
        _, warm[name], _ = mitsuba_render(timed, args.spp, 0)
        # Some samplers round the sample count (orthogonal: to the square of a prime).
        actual_spp[name] = timed.sensors()[0].sampler().sample_count()
        log(f"  {warm[name]:.2f} s, {actual_spp[name]} spp")
    rows = [("lumiere", name) for name in lumiere_samplers] + [("Mitsuba", name) for name in mitsuba_samplers]
    results = {row: {"t": [], "wall": [], "cpu": [], "mse": [], "mean": []} for row in rows}
    for seed in range(1, args.repeats + 1):
        # Alternately, so that a change of load hits every row alike.
        for renderer, name in rows:
            r = results[(renderer, name)]
            if renderer == "lumiere":
                img, stats, wall, cpu = run_lumiere(args, lumiere_camera, out / f"lumiere-{name}-{seed}.exr",
                                                    ["--mode", "path", "--max-depth", str(args.max_depth), "--spp",
                                                     str(args.spp), "--seed", str(seed), "--sampler", name])
                seconds = stats["render_ms"] / 1e3
            else:
                img, seconds, cpu = mitsuba_render(timed_scenes[name], args.spp, seed)
                wall = seconds
                write_exr(out / f"mitsuba-{name}-{seed}.exr", img)
            r["t"].append(seconds)
            r["wall"].append(wall)
            r["cpu"].append(cpu)
            r["mse"].append(float(np.mean((img - ref) ** 2)))
            r["mean"].append(float(img.mean()))
            log(f"{renderer} ({name}) seed {seed}: render {seconds:.2f} s (wall {wall:.2f} s, CPU {cpu:.2f} s), "
                f"RMSE {math.sqrt(r['mse'][-1]):.5f}")

    noise = meta["noise_mse"]
    summary = {}
    for row, r in results.items():
        t = float(np.median(r["t"]))
        cpu = float(np.median(r["cpu"]))
        mse = float(np.mean(r["mse"]))
        mean = float(np.mean(r["mean"]))
        summary[row] = {"t": t, "wall": float(np.median(r["wall"])), "cpu": cpu, "mse": mse, "rmse": math.sqrt(mse),
                        "clean": mse - noise, "bias": mean / ref_mean - 1, "eff": 1 / (t * mse),
                        "eff_cpu": 1 / (cpu * mse)}
    lumiere_rows = [row for row in rows if row[0] == "lumiere"]
    mitsuba_rows = [row for row in rows if row[0] == "Mitsuba"]
    worst_bias = max(abs(summary[row]["bias"]) for row in lumiere_rows)

    print()
    print(f"Command: `{command}`  ")
    print(f"Machine: {machine()}, 1-min load average {load:.2f} at start, {os.getloadavg()[0]:.2f} at the end "
          f"(timings assume an idle machine)  ")
    print(f"Software: lumiere {commit}, Mitsuba {mi.__version__} ({VARIANT}, Dr.Jit {dr.__version__}, "
          f"{Path(os.environ.get('DRJIT_LIBLLVM_PATH', 'LLVM')).name}), Python {platform.python_version()}  ")
    print(f"Date: {started.strftime('%Y-%m-%d %H:%M %Z')}; scene: gKit Cornell box, {width}x{height}, "
          f"path tracing max depth {args.max_depth}, {args.spp} spp, {args.threads} threads, "
          f"{args.repeats} seeds (median time, mean MSE); lumiere camera: {args.camera}  ")
    print(f"Reference: Mitsuba (independent sampler), {meta['spp']} spp ({meta['passes']} passes), mean "
          f"{ref_mean:.6f}; its own noise (MSE) {noise:.3g}, "
          + ", ".join(f"{noise / summary[row]['mse']:.1%} of {row[0]} ({row[1]})'s MSE" for row in rows) + "  ")
    print("Camera: " + "; ".join(checks))
    print()
    print("| renderer (sampler) | spp | render time (s) | wall time (s) | CPU time (s) | RMSE | RMSE without the "
          "reference's noise | mean bias (%) | efficiency 1/(t·MSE) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        s = summary[row]
        spp = args.spp if row[0] == "lumiere" else actual_spp[row[1]]
        wall = f"{s['wall']:.2f}" if row[0] == "lumiere" else "(same)"
        print(f"| {row[0]} ({row[1]}) | {spp} | {s['t']:.2f} | {wall} | {s['cpu']:.2f} | {s['rmse']:.5f} | "
              f"{math.sqrt(max(s['clean'], 0)):.5f} | {100 * s['bias']:+.3f} | {s['eff']:.4g} |")
    print()
    print("Efficiency ratio lumiere / Mitsuba (render time; with CPU time of all threads; with render time and "
          "the reference's noise taken out of both MSEs):")
    print()
    print("| lumiere \\ Mitsuba | " + " | ".join(name for _, name in mitsuba_rows) + " |")
    print("|---|" + "---|" * len(mitsuba_rows))
    for lrow in lumiere_rows:
        cells = []
        for mrow in mitsuba_rows:
            lum, mit = summary[lrow], summary[mrow]
            clean = (mit["t"] * mit["clean"]) / (lum["t"] * lum["clean"]) if lum["clean"] > 0 else float("nan")
            cells.append(f"**{lum['eff'] / mit['eff']:.2f}** (CPU {lum['eff_cpu'] / mit['eff_cpu']:.2f}; {clean:.2f})")
        print(f"| {lrow[1]} | " + " | ".join(cells) + " |")
    print()
    for row in lumiere_rows:
        verdict = "within" if abs(summary[row]["bias"]) <= 0.005 else "NOT within"
        print(f"lumiere ({row[1]})'s mean {summary[row]['bias'] * 100:+.3f}% from the reference's: {verdict} 0.5%.  ")
    print(f"lumiere's render time is its --stats-json render_ms (wall: the whole process, scene load and EXR "
          f"writing included; CPU: the whole process's); Mitsuba's is mi.render to the evaluated image after a "
          f"warm-up render per sampler (" + ", ".join(f"{name} {warm[name]:.2f} s" for name in warm)
          + ", JIT compilation included).")
    log(f"(scene files and images in {out})")
    return 0 if worst_bias <= 0.005 else 2


if __name__ == "__main__":
    sys.exit(main())
