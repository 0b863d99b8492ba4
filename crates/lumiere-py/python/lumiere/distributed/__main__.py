"""``python -m lumiere.distributed render [SCENE] --address auto -o image.exr``: the ``lumiere
render`` flags that a distributed render uses, on a Ray cluster; the image has the bytes
``lumiere render`` writes for the same flags."""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional

from .. import Camera, LumiereError, _lumiere, builtin, denoise, load, write_image
from .._denoise import _pyoidn
from .._scene import _first_repeat
from . import ClusterUnreachable, TaskFailed, _check_outputs, render_full

#: ``lumiere render``'s exit code for bad input.
EXIT_ERROR = 2


def _floats(text: str) -> tuple:
    try:
        x, y, z = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected x,y,z, got {text!r}") from None
    return (x, y, z)


def _size(text: str) -> tuple:
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from None
    return (width, height)


def _names(text: str) -> List[str]:
    return [name.strip() for name in text.split(",")]


def _emission(text: str) -> tuple:
    name, _, value = text.rpartition("=")
    if not name:
        raise argparse.ArgumentTypeError(f"expected NAME=r,g,b, got {text!r}")
    return (name, _floats(value))


def parser() -> argparse.ArgumentParser:
    main = argparse.ArgumentParser(prog="python -m lumiere.distributed", description=__doc__)
    commands = main.add_subparsers(dest="command", required=True)
    p = commands.add_parser("render", help="render a scene on a Ray cluster")
    p.add_argument("scene", nargs="?", help="OBJ file (.obj or .obj.gz); the built-in Cornell box when omitted")
    p.add_argument("--address", default="auto", help="Ray cluster: host:port, 'auto' (default), or 'local' to start one here")
    p.add_argument("-o", "--output", default="render.png", help=".png, .exr or .pfm (default render.png)")
    p.add_argument("--mode", default="path", choices=["path", "hits", "materials", "shadows", "direct", "ao"])
    p.add_argument("--spp", type=int, default=None, help="camera samples per pixel (default 8 for path, 1 otherwise)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--sampler", choices=["independent", "sobol"], help="default sobol for path, independent otherwise")
    p.add_argument("--size", type=_size, default=(1024, 768), help="WIDTHxHEIGHT (default 1024x768)")
    p.add_argument("--samples", type=int, help="direct and ao: points per light or directions (default 16)")
    p.add_argument("--light-sampling", choices=["per-light", "power"])
    p.add_argument("--ao-distance", type=float)
    p.add_argument("--max-depth", type=int, help="path: longest path in segments (default 8, 0 = no limit)")
    p.add_argument("--emission", type=_emission, action="append", default=[], metavar="NAME=r,g,b")
    p.add_argument("--orbiter", help="gKit orbiter camera file")
    p.add_argument("--eye", type=_floats)
    p.add_argument("--target", type=_floats)
    p.add_argument("--up", type=_floats, default=(0.0, 1.0, 0.0))
    p.add_argument("--fov", type=float, default=45.0)
    p.add_argument("--exposure", type=float, default=0.0, help="PNG exposure in stops")
    p.add_argument("--tonemap", choices=["clamp", "aces"], help="PNG tone mapping (default aces for path, clamp otherwise)")
    p.add_argument("--aov", type=_names, default=[], metavar="albedo,normal,depth",
                   help="extra EXR channels: first-hit colour, shading normal, distance (computed here)")
    p.add_argument("--denoise", action="store_true",
                   help="denoise with OIDN (pyoidn) here, with the albedo and normal AOVs; an .exr keeps the noisy image as the layer noisy")
    p.add_argument("--tasks", type=int, help="tasks to split the passes into (default 4 per cluster CPU)")
    p.add_argument("--threads-per-task", type=int, default=1)
    p.add_argument("--max-retries", type=int, default=3, help="reruns of a task whose worker died (default 3)")
    p.add_argument("--checkpoint", help="save the merged film here (CLI format) every --checkpoint-every seconds")
    p.add_argument("--checkpoint-every", type=float, default=60.0)
    p.add_argument("--resume", action="store_true", help="continue from --checkpoint when it exists")
    return main


def run(args: argparse.Namespace) -> int:
    # Refused now, not once the render is done (`lumiere render` checks its output first too).
    tonemap = args.tonemap or _tonemap(args.mode)
    _lumiere.check_image_output(args.output, args.exposure, tonemap)
    exr = args.output.lower().endswith(".exr")
    if args.aov and not exr:
        raise LumiereError(f"{args.output}: --aov writes extra channels, which only an .exr output can hold")
    if args.denoise:
        _pyoidn()  # Its absence is an error now, not once the render is done.
    if (args.eye is None) != (args.target is None):
        raise LumiereError("--eye and --target go together")
    twice = _first_repeat([name for name, _ in args.emission])
    if twice is not None:
        raise LumiereError(f"--emission {twice!r} is given twice")
    emission = dict(args.emission)
    scene = load(args.scene, emission) if args.scene else builtin(emission)
    if args.orbiter:
        camera: Optional[Camera] = Camera.orbiter(args.orbiter, args.size)
    elif args.eye is not None and args.target is not None:
        camera = Camera.look_at(args.eye, args.target, args.up, args.fov, args.size)
    elif scene.is_builtin:
        camera = Camera.builtin(args.size)
    else:
        camera = Camera.framing(scene, args.size, args.fov, args.up)
    # As `lumiere render`: no output may replace another or a file the render reads (the scene,
    # its MTL and textures, the orbiter), refused before any work.
    outputs = [("-o", args.output)] + ([("--checkpoint", args.checkpoint)] if args.checkpoint else [])
    _check_outputs(outputs, scene, "the scene", camera, "--orbiter")
    spp = args.spp if args.spp is not None else (8 if args.mode == "path" else 1)
    technique = {
        key: value
        for key, value in [
            ("samples", args.samples),
            ("light_sampling", args.light_sampling),
            ("ao_distance", args.ao_distance),
            ("max_depth", args.max_depth),
        ]
        if value is not None
    }
    address = None if args.address == "local" else args.address
    result = render_full(
        scene,
        camera,
        args.mode,
        spp,
        args.seed,
        sampler=args.sampler,
        address=address,
        tasks=args.tasks,
        threads_per_task=args.threads_per_task,
        max_retries=args.max_retries,
        checkpoint=args.checkpoint,
        checkpoint_every=args.checkpoint_every,
        resume=args.resume,
        aovs=args.aov + [name for name in ("albedo", "normal") if args.denoise and name not in args.aov],
        **technique,
    )
    image, layers = result.image, {name: result.aovs[name] for name in args.aov}
    # As `lumiere render --denoise`: the same filter on the same AOVs, the noisy image kept in an EXR.
    if args.denoise:
        image = denoise(result.image, result.aovs["albedo"], result.aovs["normal"])
        if exr:
            layers["noisy"] = result.image
    write_image(args.output, image, args.exposure, tonemap, aovs=layers)
    stats = result.stats
    print(
        f"{args.output}: {camera.width}x{camera.height}, {stats['samples']} spp, {len(stats['tasks'])} tasks on "
        f"{stats['cpus']} CPUs, {stats['seconds']:.2f} s, {stats['rays'] / max(stats['seconds'], 1e-9) / 1e6:.1f} Mrays/s",
        file=sys.stderr,
    )
    return 0


def _tonemap(mode: str) -> str:
    """``lumiere render``'s tone mapping for a mode's PNG: filmic for path tracing."""
    return "aces" if mode == "path" else "clamp"


def main(argv: Optional[List[str]] = None) -> int:
    args = parser().parse_args(argv)
    try:
        return run(args)
    except (LumiereError, ClusterUnreachable, ImportError) as e:
        print(f"lumiere.distributed: error: {e}", file=sys.stderr)
        return EXIT_ERROR
    except TaskFailed as e:
        print(f"lumiere.distributed: error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("lumiere.distributed: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
