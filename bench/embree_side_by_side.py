#!/usr/bin/env python3
"""lumiere beside embree_native --packet 1, row by row, in one run (BENCHMARKS.md, "Beside Embree").

For each row of the lab table (built-in Cornell box, 1024x768) and the two bunny-1m rows, runs
lumiere and then Embree (the peer in ../shared/peers/embree-native) for each repeat, so that a
change of load hits both; first with --threads T (the times), then with --threads 1 (cycles per
ray). Prints a Markdown table ready for BENCHMARKS.md on stdout, progress on stderr.

Standard library only. Run it from anywhere; bench/README.md documents it.
"""

import argparse
import datetime
import gzip
import json
import os
import resource
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from array import array

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

BUILD_PEER = (
    "build it: apt-get install -y libembree-dev cmake g++ && "
    "cmake -S ../shared/peers/embree-native -B /tmp/embree-native -DCMAKE_BUILD_TYPE=Release && "
    "cmake --build /tmp/embree-native -j2 (see ../shared/peers/embree-native/README.md), or pass --embree PATH"
)

# The bunny-1m camera of the peer's README, in both renderers' spellings.
BUNNY_EYE = (-0.016841, 0.110154, 0.338463)
BUNNY_TARGET = (-0.016841, 0.110154, -0.001537)
BUNNY_UP = (0, 1, 0)
BUNNY_FOV = 30


class Row:
    def __init__(self, key, label, scene, mode, samples, lab_ms, target_embree, target_lab):
        self.key = key
        self.label = label
        self.scene = scene  # "cornell" or "bunny-1m"
        self.mode = mode  # the same name in both renderers
        self.samples = samples  # --samples N, or None
        self.lab_ms = lab_ms  # the lab's parallel figure at 1024x768, or None
        self.target_embree = target_embree  # issue 11: at least this many times Embree's speed
        self.target_lab = target_lab  # issue 11: at least this many times the lab's speed, or None


ROWS = [
    Row("shadows", "hard shadows", "cornell", "shadows", None, 272, 2.0, 30.0),
    Row("soft16", "soft N=16", "cornell", "direct", 16, 2891, 2.0, 30.0),
    Row("soft64", "soft N=64", "cornell", "direct", 64, 11506, 2.0, 30.0),
    Row("soft256", "soft N=256", "cornell", "direct", 256, 46847, 2.0, 30.0),
    Row("ao16", "AO N=16", "cornell", "ao", 16, 1817, 2.0, 30.0),
    Row("ao64", "AO N=64", "cornell", "ao", 64, 6954, 2.0, 30.0),
    Row("ao256", "AO N=256", "cornell", "ao", 256, 26914, 2.0, 30.0),
    # The lab's hit mask, as each renderer computes it: lumiere asks whether a camera ray hits
    # anything (any hit, packets), the peer for its closest hit (rtcIntersect1).
    Row("bunny-hits", "bunny 1.1M hits", "bunny-1m", "hits", None, None, 2.0, None),
    # The same query on both sides: each camera ray's closest hit and its material.
    Row("bunny-closest", "bunny 1.1M closest hits (materials)", "bunny-1m", "materials", None, None, None, None),
    Row("bunny-ao16", "bunny 1.1M AO N=16", "bunny-1m", "ao", 16, None, 1.5, None),
]
QUICK_ROWS = ["shadows", "soft16"]


def fail(message):
    print(f"embree_side_by_side: error: {message}", file=sys.stderr)
    sys.exit(2)


def progress(message):
    print(f"[{time.strftime('%H:%M:%S')}] {message}", file=sys.stderr, flush=True)


# ---------------------------------------------------------------- machine


def cpuinfo():
    """CPU model, the first "cpu MHz" and the flags, from /proc/cpuinfo."""
    model, mhz, flags = "unknown CPU", None, set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                key, value = key.strip(), value.strip()
                if key == "model name" and model == "unknown CPU":
                    model = value
                elif key == "cpu MHz" and mhz is None:
                    mhz = float(value)
                elif key == "flags" and not flags:
                    flags = set(value.split())
    except OSError:
        pass
    return model, mhz, flags


def hypervisor(flags):
    """'KVM' (lscpu's hypervisor vendor) under a hypervisor, None on bare metal."""
    if "hypervisor" not in flags:
        return None
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10).stdout
        for line in out.splitlines():
            if line.startswith("Hypervisor vendor:"):
                return line.split(":", 1)[1].strip()
    except (OSError, subprocess.SubprocessError):
        pass
    return "a hypervisor"


def git_commit():
    try:
        run = lambda *a: subprocess.run(["git", "-C", REPO, *a], capture_output=True, text=True, timeout=30)
        commit = run("rev-parse", "--short", "HEAD").stdout.strip() or "unknown"
        dirty = run("status", "--porcelain", "--untracked-files=no").stdout.strip()
        return commit + (" (with uncommitted changes)" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def lumiere_build(binary, commit=None):
    """Which lumiere a table is of: the commit the binary's statistics name; for a binary too old
    to name it, the work tree's commit for the tree's own build, else the binary's path."""
    if commit:
        return f"`{commit}` (the binary's)"
    if os.path.realpath(binary) == os.path.realpath(os.path.join(REPO, "target", "release", "lumiere")):
        return f"`{git_commit()}`"
    return f"the binary `{binary}` (not this work tree's build, which is at `{git_commit()}`)"


def embree_version():
    try:
        out = subprocess.run(
            ["dpkg-query", "-W", "-f", "${Version}", "libembree3-3"], capture_output=True, text=True, timeout=10
        )
        if out.returncode == 0 and out.stdout.strip():
            return f"Embree {out.stdout.strip()} (Debian libembree3-3)"
    except (OSError, subprocess.SubprocessError):
        pass
    return "Embree 3 (version unknown)"


def cpu_busy_jiffies():
    """Busy jiffies of all CPUs together (everything but idle and iowait), from /proc/stat."""
    try:
        with open("/proc/stat") as f:
            fields = [int(v) for v in f.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0)
    return sum(fields[:8]) - idle


# ---------------------------------------------------------------- running


def children_cpu_s():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_process(argv, label):
    """Runs argv; returns (stdout, other_cores): the CPU the rest of the machine used meanwhile, in
    cores, over the whole process (its own CPU time, from the reaped children's rusage, taken out)."""
    hz = os.sysconf("SC_CLK_TCK")
    busy0, own0, t0 = cpu_busy_jiffies(), children_cpu_s(), time.monotonic()
    try:
        proc = subprocess.run(argv, capture_output=True, text=True)
    except OSError as e:
        fail(f"{label}: cannot run {argv[0]}: {e}")
    wall = time.monotonic() - t0
    busy1, own = cpu_busy_jiffies(), children_cpu_s() - own0
    if proc.returncode != 0:
        lines = [line.strip() for line in proc.stderr.splitlines() if line.strip()] or ["(no message)"]
        message = next((line for line in lines if "error" in line.lower()), lines[-1])
        fail(f"{label} exited with {proc.returncode}: {message}; command: {shlex.join(argv)}")
    other = None
    if busy0 is not None and busy1 is not None and wall > 0:
        other = max(0.0, ((busy1 - busy0) / hz - own) / wall)
    return proc.stdout, other


class Runner:
    def __init__(self, args, tmp):
        self.args = args
        self.tmp = tmp
        self.scenes = {}
        self.isa = None  # lumiere's, from its statistics
        self.commit = None  # the binary's, from its statistics
        self.other = {"lumiere": 0.0, "Embree": 0.0}

    def scene_path(self, scene):
        """The OBJ file of a scene for the peer (and for lumiere outside the built-in box)."""
        if scene in self.scenes:
            return self.scenes[scene]
        if scene == "cornell":
            path = os.path.join(self.args.scenes_dir, "cornell", "cornell.obj")
            if not os.path.isfile(path):
                fail(f"{path} not found (the peer renders it; pass --scenes-dir)")
        else:
            packed = os.path.join(self.args.scenes_dir, "bunny-1m", "stanford-bunny-1m.obj.gz")
            if not os.path.isfile(packed):
                fail(f"{packed} not found (pass --scenes-dir)")
            path = os.path.join(self.tmp, "stanford-bunny-1m.obj")
            progress(f"gunzipping {packed} into {path}")
            with gzip.open(packed, "rb") as src, open(path, "wb") as dst:
                shutil.copyfileobj(src, dst, 1 << 20)
        self.scenes[scene] = path
        return path

    def lumiere(self, row, threads, mode=None, image=None):
        """lumiere's render loop in ms, its ray count and its statistics."""
        mode = mode or row.mode
        stats = os.path.join(self.tmp, "lumiere-stats.json")
        image = image or os.path.join(self.tmp, "lumiere.pfm")
        argv = [self.args.lumiere, "render"]
        if row.scene != "cornell":  # the built-in box is the lab's Cornell box with gKit's 2022 orbiter
            argv += [self.scene_path(row.scene)]
            argv += ["--eye", ",".join(map(str, BUNNY_EYE)), "--target", ",".join(map(str, BUNNY_TARGET))]
            argv += ["--up", ",".join(map(str, BUNNY_UP)), "--fov", str(BUNNY_FOV)]
        argv += ["--mode", mode]
        if row.samples and mode == row.mode:
            argv += ["--samples", str(row.samples)]
        argv += ["--size", "1024x768", "--threads", str(threads), "--stats-json", stats, "-o", image]
        if self.args.isa:
            argv += ["--isa", self.args.isa]
        _, other = run_process(argv, "lumiere")
        if other is not None:
            self.other["lumiere"] = max(self.other["lumiere"], other)
        with open(stats) as f:
            s = json.load(f)
        self.isa = s.get("isa", self.isa)
        self.commit = s.get("commit", self.commit)
        return float(s["render_ms"]), int(s["rays"]), s

    def embree(self, row, threads, mode=None, image=None):
        """Embree's render loop in ms (one timed run in a fresh process) and its ray count."""
        mode = mode or row.mode
        argv = [self.args.embree, "--scene", self.scene_path(row.scene), "--mode", mode]
        if row.scene != "cornell":
            argv += ["--lookat", *map(str, BUNNY_EYE), *map(str, BUNNY_TARGET), *map(str, BUNNY_UP)]
            argv += ["--fov", str(BUNNY_FOV)]
        if row.samples and mode == row.mode:
            argv += ["--samples", str(row.samples)]
        argv += ["--width", "1024", "--height", "768", "--threads", str(threads), "--packet", "1"]
        # Shadow rays whose light point cannot contribute (behind the surface or the light) are not
        # traced, as lumiere does not trace them: both renderers trace the same rays. (The peer's
        # default, the lab's count, traces 12-18% more on the shadow rows.)
        argv += ["--cull", "1"]
        argv += ["--repeat", "1", "--warmup", "0"]
        if image:
            argv += ["--out", image]
        stdout, _ = run_process(argv, "embree_native")
        result = [line for line in stdout.splitlines() if line.startswith("RESULT,")]
        if not result:
            fail(f"embree_native printed no RESULT line (mode {mode}; a scene without lights?); command: {shlex.join(argv)}")
        fields = result[-1].split(",")
        # RESULT,tag,mode,N,threads,packet,primary8,rays,median_ms,Mrays/s,build_ms,max_other_cores,runs_ms
        self.other["Embree"] = max(self.other["Embree"], float(fields[11]))
        return float(fields[8]), int(fields[7])


# ---------------------------------------------------------------- images


def read_pfm(path):
    """(width, height, floats) of a PFM file, rows in file order (both renderers: bottom to top)."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = array("f")
        data.frombytes(f.read())
    channels = 3 if kind == b"PF" else 1
    if (scale < 0) != (sys.byteorder == "little"):
        data.byteswap()
    if len(data) != width * height * channels:
        fail(f"{path}: {len(data)} floats for a {width}x{height} image")
    if channels == 3:
        data = [max(data[i], data[i + 1], data[i + 2]) for i in range(0, len(data), 3)]
    return width, height, data


def camera_check(runner, scene, threads):
    """Renders --mode hits with both and compares where the camera rays hit: (differing, hit by
    lumiere, hit by Embree, pixels)."""
    row = next(r for r in ROWS if r.scene == scene)
    lum, emb = os.path.join(runner.tmp, f"check-{scene}-lumiere.pfm"), os.path.join(runner.tmp, f"check-{scene}-embree.pfm")
    runner.lumiere(row, threads, mode="hits", image=lum)
    runner.embree(row, threads, mode="hits", image=emb)
    wl, hl, a = read_pfm(lum)
    we, he, b = read_pfm(emb)
    if (wl, hl) != (we, he):
        fail(f"camera check on {scene}: lumiere's image is {wl}x{hl}, Embree's {we}x{he}")
    differ = sum((x > 0) != (y > 0) for x, y in zip(a, b))
    return differ, sum(x > 0 for x in a), sum(y > 0 for y in b), len(a)


# ---------------------------------------------------------------- table


def fmt_ms(ms):
    if ms is None:
        return "–"
    return f"{ms:,.0f}" if ms >= 100 else f"{ms:.1f}"


def fmt_ratio(r):
    return "–" if r is None else f"{r:.2f}x"


def fmt_cycles(c):
    return "–" if c is None else f"{c:,.0f}"


def target_text(row, vs_embree, vs_lab):
    if row.target_embree is None:
        return "none (the hits row's query, the same on both sides)"
    parts = [f"{row.target_embree:g}x Embree: {'met' if vs_embree >= row.target_embree else 'not met'}"]
    if row.target_lab and vs_lab is not None:
        parts.append(
            f"{row.target_lab:g}x lab (≤ {row.lab_ms / row.target_lab:,.0f} ms): {'met' if vs_lab >= row.target_lab else 'not met'}"
        )
    return "; ".join(parts)


def main():
    parser = argparse.ArgumentParser(
        description="lumiere beside embree_native --packet 1 on the lab's rows and the bunny-1m rows, "
        "interleaved in one run; prints a Markdown table for BENCHMARKS.md."
    )
    parser.add_argument("--repeats", type=int, default=3, help="runs of each renderer per row and thread count; the median is kept (default 3)")
    parser.add_argument("--threads", type=int, default=2, help="threads of the timed pass, both renderers (default 2)")
    parser.add_argument(
        "--rows",
        default=None,
        help="comma-separated subset of: " + ",".join(r.key for r in ROWS) + " (default: all)",
    )
    parser.add_argument("--lumiere", default=os.path.join(REPO, "target", "release", "lumiere"), help="lumiere binary (default ./target/release/lumiere)")
    parser.add_argument(
        "--embree",
        default=os.environ.get("EMBREE_NATIVE", "/tmp/embree-native/embree_native"),
        help="embree_native binary (default $EMBREE_NATIVE or /tmp/embree-native/embree_native)",
    )
    parser.add_argument("--scenes-dir", default=os.path.join(os.path.dirname(REPO), "shared", "scenes"), help="the shared scenes (default ../shared/scenes)")
    parser.add_argument("--isa", default=None, help="passed through to lumiere render --isa (default: lumiere's choice)")
    parser.add_argument("--single-repeats", type=int, default=None, help="runs per renderer and row at 1 thread, for cycles per ray; 0 skips that pass (default: --repeats)")
    parser.add_argument("--quick", action="store_true", help="smoke test: 1 repeat, hard shadows and soft N=16 only (still 1024x768)")
    args = parser.parse_args()

    if args.quick:
        args.repeats = 1
        if args.rows is None:
            args.rows = ",".join(QUICK_ROWS)
    if args.single_repeats is None:
        args.single_repeats = args.repeats
    if args.repeats < 1 or args.threads < 1 or args.single_repeats < 0:
        fail("--repeats and --threads must be at least 1, --single-repeats at least 0")
    keys = [r.key for r in ROWS]
    wanted = keys if args.rows is None else [k.strip() for k in args.rows.split(",") if k.strip()]
    unknown = [k for k in wanted if k not in keys]
    if unknown or not wanted:
        fail(f"unknown --rows {','.join(unknown) or '(empty)'}; choose among {','.join(keys)}")
    rows = [r for r in ROWS if r.key in wanted]

    args.lumiere = os.path.abspath(args.lumiere)
    args.embree = os.path.abspath(args.embree)
    args.scenes_dir = os.path.abspath(args.scenes_dir)
    if not (os.path.isfile(args.lumiere) and os.access(args.lumiere, os.X_OK)):
        fail(f"lumiere not found at {args.lumiere}: run `cargo build --release` at the repository root, or pass --lumiere PATH")
    if not (os.path.isfile(args.embree) and os.access(args.embree, os.X_OK)):
        fail(f"embree_native not found at {args.embree}: {BUILD_PEER}")

    script = os.path.relpath(os.path.abspath(__file__), os.getcwd())
    if script.startswith(".."):
        script = os.path.abspath(__file__)
    command = "python3 " + shlex.join([script, *sys.argv[1:]])
    model, mhz, flags = cpuinfo()
    hyper = hypervisor(flags)
    cores = os.cpu_count()
    load_before = os.getloadavg()
    started = datetime.datetime.now(datetime.timezone.utc)

    with tempfile.TemporaryDirectory(prefix="lumiere-embree-") as tmp:
        runner = Runner(args, tmp)

        # Both renderers must see the same pixels: compare where their camera rays hit.
        checks = {}
        for scene in dict.fromkeys(r.scene for r in rows):
            progress(f"camera check on {scene}: --mode hits with both")
            checks[scene] = camera_check(runner, scene, args.threads)

        results = []
        for i, row in enumerate(rows, 1):
            name = f"row {i}/{len(rows)} {row.label}"
            res = {"lumiere": [], "embree": [], "lumiere1": [], "embree1": [], "rays": None, "rays1": None}
            for threads, reps, lk, ek in ((args.threads, args.repeats, "lumiere", "embree"), (1, args.single_repeats, "lumiere1", "embree1")):
                for rep in range(1, reps + 1):
                    l_ms, l_rays, _ = runner.lumiere(row, threads)
                    e_ms, e_rays = runner.embree(row, threads)
                    res[lk].append((l_ms, l_rays))
                    res[ek].append((e_ms, e_rays))
                    progress(f"{name}: repeat {rep}/{reps}, {threads} thread{'s' * (threads > 1)}: lumiere {l_ms:,.1f} ms, Embree {e_ms:,.1f} ms")
            results.append((row, res))

    load_after = os.getloadavg()

    def median_ms(runs):
        return statistics.median(ms for ms, _ in runs) if runs else None

    def cycles(runs):
        # CPU time of the render loop at 1 thread (its wall time: one thread, nothing else to wait
        # for) x clock / rays; median over the runs.
        if not runs or not mhz:
            return None
        return statistics.median(ms * 1e-3 * mhz * 1e6 / rays for ms, rays in runs)

    # ---- header
    out = []
    out.append(f"`{command}`")
    out.append("")
    out.append(
        f"on **{started:%Y-%m-%d}** ({started:%H:%M} UTC), {model}, {cores} cores"
        + (f" under {hyper}" if hyper else "")
        + f", {', '.join(f for f in ('avx512f', 'avx2', 'fma') if f in flags) or 'no AVX'}; "
        f"load average {load_before[0]:.2f} before, {load_after[0]:.2f} after (1-minute); "
        f"lumiere at {lumiere_build(args.lumiere, runner.commit)}, ISA `{runner.isa or 'unknown (no isa in its statistics)'}`; {embree_version()}, `embree_native --packet 1 --cull 1` "
        f"(rtcIntersect1 camera rays, rtcOccluded8 shadow/AO rays; `--cull 1`: no shadow ray whose light point "
        f"cannot contribute, as in lumiere, so both trace the same rays)."
    )
    out.append("")
    out.append(
        f"Each repeat runs lumiere then Embree, each in a fresh process; times are the render loop only "
        f"(lumiere: `render_ms` of `lumiere render --mode M [--samples N] --threads T --stats-json`; Embree: "
        f"`median_ms` of the `RESULT` line of `embree_native --mode M [--samples N] --threads T --packet 1 "
        f"--cull 1 --repeat 1`), median of {args.repeats} at {args.threads} thread{'s' * (args.threads > 1)}, 1024x768; "
        f"Cornell rows on the built-in box (lumiere) and `cornell/cornell.obj` with its 2022 orbiter (Embree); "
        f"bunny rows on `bunny-1m` with `--lookat {' '.join(map(str, BUNNY_EYE + BUNNY_TARGET + BUNNY_UP))} "
        f"--fov {BUNNY_FOV}` (lumiere: `--eye/--target/--up/--fov`)."
    )
    out.append("")
    if args.single_repeats:
        clock = f"{mhz:.0f} MHz" if mhz else "unknown (no `cpu MHz` in /proc/cpuinfo: cycles not computed)"
        out.append(
            f"Cycles per ray = t1 x f / rays: t1 = the render loop's time with `--threads 1` (one thread, so its "
            f"CPU time; median of {args.single_repeats}), f = {clock}, the `cpu MHz` of /proc/cpuinfo"
            + (f" (under {hyper}: the host's nominal clock, not a measured one; turbo is not seen)" if hyper else " (nominal)")
            + ", rays = each renderer's own count (camera rays + shadow/AO rays: lumiere's `rays`, Embree's RESULT `rays`)."
        )
        out.append("")
    for scene, (differ, hit_l, hit_e, total) in checks.items():
        verdict = "the same framing" if differ <= total * 0.001 else "**DIFFERENT FRAMING: the rows are not comparable**"
        out.append(
            f"Camera check ({scene}, `--mode hits`, hit masks of the two PFMs): {differ} of {total} pixels differ "
            f"({100 * differ / total:.3f}%; lumiere hits {hit_l}, Embree {hit_e}): {verdict}."
        )
    out.append("")

    head = ["row", "lab parallel ms", "lumiere ms", "Embree ms", "lumiere vs Embree", "lumiere vs lab"]
    if args.single_repeats:
        head += ["lumiere cycles/ray (1 thread)", "Embree cycles/ray (1 thread)"]
    head += ["issue 11 target"]
    out.append("| " + " | ".join(head) + " |")
    out.append("|" + "---|" * len(head))
    notes = []
    for row, res in results:
        l_ms, e_ms = median_ms(res["lumiere"]), median_ms(res["embree"])
        vs_embree = e_ms / l_ms
        vs_lab = row.lab_ms / l_ms if row.lab_ms else None
        cells = [row.label, fmt_ms(row.lab_ms), fmt_ms(l_ms), fmt_ms(e_ms), fmt_ratio(vs_embree), fmt_ratio(vs_lab)]
        if args.single_repeats:
            cells += [fmt_cycles(cycles(res["lumiere1"])), fmt_cycles(cycles(res["embree1"]))]
        cells.append(target_text(row, vs_embree, vs_lab))
        out.append("| " + " | ".join(cells) + " |")
        l_rays, e_rays = res["lumiere"][0][1], res["embree"][0][1]
        if abs(l_rays - e_rays) > 0.01 * max(l_rays, e_rays):
            notes.append(f"{row.label}: lumiere traces {l_rays:,} rays, Embree {e_rays:,}")
    out.append("")
    if notes:
        out.append("Ray counts that differ by more than 1% (cycles per ray use each renderer's own): " + "; ".join(notes) + ".")
        out.append("")
    out.append(
        f"Other processes meanwhile: up to {runner.other['Embree']:.2f} cores during Embree's render loops "
        f"(its own probe), up to {runner.other['lumiere']:.2f} cores during lumiere's processes (whole process, "
        f"from /proc/stat); above ~0.1 the run was disturbed."
    )
    print("\n".join(out))
    sys.stdout.flush()
    if any(d > t * 0.001 for d, _, _, t in checks.values()):
        sys.exit(1)


if __name__ == "__main__":
    try:
        main()
    except KeyboardInterrupt:
        print("embree_side_by_side: interrupted", file=sys.stderr)
        sys.exit(130)
