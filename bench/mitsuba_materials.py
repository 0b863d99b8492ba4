#!/usr/bin/env python3
"""Glass and metals against Mitsuba 3: does lumiere converge to the same image where the models agree?

The gKit Cornell box with its short box made of smooth glass (MTL `illum 7`, `Ni 1.5`, `Kd 0`,
`Ks 1`: lumiere's dielectric, exact Fresnel), its tall box a white mirror (`illum 3`, `Kd 0`,
`Ks 1`: lumiere's mirror, Schlick `F` with `F0` 1, which is 1) and its back wall a white rough
metal (`Pm 1`, `Pr 0.316228`: GGX of alpha 0.1), against Mitsuba's `dielectric` (`int_ior` 1.5),
`conductor` and `roughconductor` (GGX, alpha 0.1) of reflectance 1, with the same shapes, camera,
emitter and depth as bench/mitsuba_compare.py. Both render the scene with several seeds; the image is cut into a
grid of cells, and each cell's mean is compared between the renderers with the standard error the
seeds' spread gives: a |z| above 4 in the image mean or in a cell says that they disagree there
(caustics through the glass have heavy tails, so a cell may reach 3 by chance more often than a
normal law says). Prints a Markdown report; exit code 2 when they disagree. See bench/README.md.

Requires what bench/mitsuba_compare.py requires (numpy, mitsuba, an LLVM shared library).
"""

from __future__ import annotations

import argparse
import datetime
import math
import os
import shlex
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mitsuba_compare as mc  # noqa: E402 - the shared scene, camera and renderer helpers

# The materials changed, by MTL material name: lumiere's statements and Mitsuba's BSDF.
MATERIALS = [
    ("shortBox.001", ["Kd 0 0 0", "Ks 1 1 1", "Ni 1.5", "illum 7"],
     {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}),
    # lumiere's opaque surfaces are two-sided; Mitsuba's conductors are not.
    ("tallBox.001", ["Kd 0 0 0", "Ks 1 1 1", "illum 3"],
     {"type": "twosided", "material": {"type": "conductor", "material": "none"}}),
    # GGX alpha = Pr^2 = 0.1. Mitsuba's masking is Smith's separable G1(wo) G1(wi), lumiere's the
    # height-correlated G2: they differ by a term in Lambda(wo) Lambda(wi), about 1e-4 at this
    # roughness away from grazing angles, far below the noise.
    ("backWall.001", ["Kd 1 1 1", "Pm 1", "Pr 0.316228"],
     {"type": "twosided", "material": {"type": "roughconductor", "material": "none", "distribution": "ggx",
                                       "alpha": 0.1}}),
]


def write_lumiere_scene(folder: Path) -> Path:
    """cornell.obj beside an MTL with `MATERIALS`' statements; returns the OBJ's path."""
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(mc.CORNELL / "cornell.obj", folder / "cornell.obj")
    replaced = {name: statements for name, statements, _ in MATERIALS}
    lines, current = [], None
    for line in (mc.CORNELL / "cornell.mtl").read_text().splitlines():
        tokens = line.split()
        if tokens and tokens[0] == "newmtl":
            current = tokens[1]
            lines.append(line)
            if current in replaced:
                lines.extend([*replaced[current], ""])
        elif current not in replaced:
            lines.append(line)
    (folder / "cornell.mtl").write_text("\n".join(lines) + "\n")
    return folder / "cornell.obj"


def cell_means(images: list[np.ndarray], grid: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Each cell's mean over its pixels and channels, and the variance of that mean: the per-pixel
    variance of the seeds' mean (from their spread), summed over the cell and divided by its
    number of pixels squared. Pixels are independent in both renderers (each pixel draws its own
    numbers); a pixel's channels are not (one path carries all three), so they are averaged first."""
    stack = np.stack(images).mean(axis=-1)
    k = len(images)
    mean = stack.mean(axis=0)
    var_of_mean = stack.var(axis=0, ddof=1) / k
    h, w = mean.shape[:2]
    gx, gy = grid
    means = np.zeros((gy, gx))
    variances = np.zeros((gy, gx))
    for j in range(gy):
        for i in range(gx):
            ys, xs = slice(j * h // gy, (j + 1) * h // gy), slice(i * w // gx, (i + 1) * w // gx)
            n = mean[ys, xs].size
            means[j, i] = mean[ys, xs].mean()
            variances[j, i] = var_of_mean[ys, xs].sum() / (n * n)
    return means, variances


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lumiere", default=str(mc.REPO / "target" / "release" / "lumiere"),
                    help="lumiere binary (default ./target/release/lumiere)")
    ap.add_argument("--size", default="256x192", help="WIDTHxHEIGHT (default %(default)s)")
    ap.add_argument("--spp", type=int, default=256, help="samples per pixel of each render (default %(default)s)")
    ap.add_argument("--seeds", type=int, default=8, help="renders per renderer, seeds 1..N (default %(default)s)")
    ap.add_argument("--max-depth", type=int, default=8, help="path length, Mitsuba's count (default %(default)s)")
    ap.add_argument("--grid", default="8x6", help="cells compared, COLUMNSxROWS (default %(default)s)")
    ap.add_argument("--threads", type=int, default=2, help="threads for both renderers (default %(default)s)")
    ap.add_argument("--out", help="folder for the scene files and images (default: a new temporary folder)")
    args = ap.parse_args()

    def log(msg: str) -> None:
        print(msg, file=sys.stderr, flush=True)

    width, height = (int(x) for x in args.size.lower().split("x"))
    grid = tuple(int(x) for x in args.grid.lower().split("x"))
    if args.seeds < 2:
        ap.error("--seeds must be at least 2: the seeds' spread gives the standard errors")
    if not Path(args.lumiere).exists():
        ap.error(f"{args.lumiere} not found: run `cargo build --release` first")
    if "DRJIT_LIBLLVM_PATH" not in os.environ and (lib := mc.find_libllvm()):
        os.environ["DRJIT_LIBLLVM_PATH"] = lib
    import drjit as dr
    import mitsuba as mi

    try:
        mi.set_variant(mc.VARIANT)
    except Exception as e:  # noqa: BLE001 - the message says what is missing
        raise SystemExit(f"mitsuba variant {mc.VARIANT} failed ({e}); see bench/README.md")
    dr.set_thread_count(args.threads)
    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="lumiere-materials-"))
    out.mkdir(parents=True, exist_ok=True)
    started = datetime.datetime.now().astimezone()

    obj = write_lumiere_scene(out / "lumiere")
    (out / "mitsuba").mkdir(exist_ok=True)
    shapes = mc.write_scene_files(out / "mitsuba", log)
    orbiter_file = mc.CORNELL / "cornell_orbiter.txt"
    eye, target, up = mc.orbiter_look_at(mc.read_orbiter(orbiter_file))
    integrator = {"type": "path", "max_depth": args.max_depth, "rr_depth": 5, "hide_emitters": False}
    scene_dict = mc.mitsuba_scene_dict(shapes, eye, target, up, width, height, integrator)
    bsdfs = {name: bsdf for name, _, bsdf in MATERIALS}
    for i, shape in enumerate(shapes):
        if shape["name"] in bsdfs:
            scene_dict[f"shape_{i:02d}"]["bsdf"] = bsdfs.pop(shape["name"])
    if bsdfs:
        raise SystemExit(f"no shape for {sorted(bsdfs)} in cornell.obj")
    scene = mi.load_dict(scene_dict)

    images = {"lumiere": [], "Mitsuba": []}
    for seed in range(1, args.seeds + 1):
        exr = out / f"lumiere-{seed}.exr"
        img, stats, *_ = mc.run_lumiere(args, ["--orbiter", str(orbiter_file)], exr,
                                        [str(obj), "--mode", "path", "--max-depth", str(args.max_depth),
                                         "--spp", str(args.spp), "--seed", str(seed)])
        images["lumiere"].append(img)
        img, seconds, _ = mc.mitsuba_render(scene, args.spp, seed)
        mc.write_exr(out / f"mitsuba-{seed}.exr", img)
        images["Mitsuba"].append(img)
        log(f"seed {seed}: lumiere {stats['render_ms'] / 1e3:.1f} s, Mitsuba {seconds:.1f} s")
    for name, imgs in images.items():
        mc.write_exr(out / f"{name}-mean.exr", np.mean(imgs, axis=0))

    (lm, lv), (mm, mv) = cell_means(images["lumiere"], grid), cell_means(images["Mitsuba"], grid)
    z = (lm - mm) / np.sqrt(lv + mv)
    (lm1, lv1), (mm1, mv1) = cell_means(images["lumiere"], (1, 1)), cell_means(images["Mitsuba"], (1, 1))
    z_image = float((lm1 - mm1)[0, 0] / math.sqrt((lv1 + mv1)[0, 0]))
    worst = float(np.abs(z).max())

    print(f"Command: `{shlex.join(['python3', *sys.argv])}`  ")
    print(f"Machine: {mc.machine()}  ")
    print(f"Software: lumiere {mc.lumiere_commit()}, Mitsuba {mi.__version__} ({mc.VARIANT})  ")
    print(f"Date: {started.strftime('%Y-%m-%d %H:%M %Z')}; gKit Cornell box with a glass short box, a mirror "
          f"tall box and a rough metal back wall, {width}x{height}, max depth {args.max_depth}, {args.spp} spp x {args.seeds} seeds each  ")
    print()
    print(f"Image mean: lumiere {lm1[0, 0]:.6f}, Mitsuba {mm1[0, 0]:.6f} "
          f"({(lm1[0, 0] / mm1[0, 0] - 1) * 100:+.3f}%, z = {z_image:+.2f})  ")
    print(f"Cells ({grid[0]}x{grid[1]}): largest |z| {worst:.2f}; |z| above 3 in "
          f"{int(np.count_nonzero(np.abs(z) > 3))} of {z.size}")
    print()
    print("| row \\ column | " + " | ".join(str(i) for i in range(grid[0])) + " |")
    print("|---|" + "---|" * grid[0])
    for j in range(grid[1]):
        cells = [f"{(lm[j, i] / mm[j, i] - 1) * 100:+.2f}% ({z[j, i]:+.1f})" for i in range(grid[0])]
        print(f"| {j} | " + " | ".join(cells) + " |")
    print()
    print("Each cell: lumiere's mean against Mitsuba's, and z = the difference over its standard error.")
    agree = worst <= 4 and abs(z_image) <= 4
    print(f"Verdict: the renderers {'agree' if agree else 'DISAGREE'} (every |z| at most 4).")
    log(f"(scene files and images in {out})")
    return 0 if agree else 2


if __name__ == "__main__":
    sys.exit(main())
