"""lumiere.distributed on a real Ray cluster on 127.0.0.1 (a head and one more node, one CPU
each, started here and stopped at the end): the bytes of a local render whatever the split, a
worker killed mid-task changes nothing, checkpoints the CLI resumes, and a clear error when no
cluster answers."""

import os
import signal
import struct
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import lumiere

from conftest import optional  # noqa: E402

ray = optional("ray", "pip install ray")
from ray.cluster_utils import Cluster  # noqa: E402

import lumiere.distributed as distributed  # noqa: E402
from conftest import read_pfm  # noqa: E402


def bits(image):
    return np.ascontiguousarray(image, dtype=np.float32).view(np.uint32)


def checkpoint_header(path):
    """A checkpoint's samples per pixel and rendering seconds (the layout in checkpoint.rs)."""
    head = path.read_bytes()[:72]
    return struct.unpack_from("<I", head, 36)[0], struct.unpack_from("<d", head, 64)[0]


@pytest.fixture(scope="module")
def cluster():
    """A head node and a worker node, separate raylet processes on 127.0.0.1, one CPU each."""
    start = time.perf_counter()
    cluster = Cluster(
        initialize_head=True,
        head_node_args={"num_cpus": 1, "include_dashboard": False, "node_ip_address": "127.0.0.1"},
    )
    try:
        cluster.add_node(num_cpus=1, node_ip_address="127.0.0.1")
        ray.init(address=cluster.address, logging_level="warning")
        assert len([n for n in ray.nodes() if n["Alive"]]) == 2
        assert time.perf_counter() - start < 120, "the cluster started in time"
        yield cluster
    finally:
        ray.shutdown()
        cluster.shutdown()


@pytest.fixture(autouse=True)
def no_ray_cancel(monkeypatch):
    """``ray.cancel`` is never called: cancelling a task at the moment its result arrives aborts
    the driver process in Ray (``Tried to complete task that was not pending``), which it did in
    this file's test of a stale scene, one run in four. Tasks stop by themselves instead."""
    calls = []
    monkeypatch.setattr(ray, "cancel", lambda *args, **kwargs: calls.append(args))
    yield
    assert not calls, "ray.cancel was called"


def test_bytes_equal_a_local_render_whatever_the_split(cluster):
    scene = lumiere.builtin()
    local = lumiere.render(scene, spp=12, size=(64, 48), seed=4)
    for tasks in (1, 5, 12):
        result = distributed.render_full(scene, spp=12, size=(64, 48), seed=4, address=cluster.address, tasks=tasks)
        assert np.array_equal(bits(result.image), bits(local)), f"{tasks} tasks"
        assert result.stats["samples"] == 12 and len(result.stats["tasks"]) == tasks
    # Another technique, another camera, a scene from arrays.
    camera = lumiere.Camera.look_at((0, 1, 3.5), (0, 1, 0), size=(40, 30))
    local = lumiere.render(scene, camera, mode="direct", spp=5, samples=2)
    remote = distributed.render(scene, camera, mode="direct", spp=5, samples=2, address=cluster.address, tasks=3)
    assert np.array_equal(bits(remote), bits(local))
    # With AOVs: the same dict, AOVs computed on the driver.
    aovs = ("depth", "albedo", "normal")
    local = lumiere.render(scene, camera, mode="ao", spp=3, samples=2, aovs=aovs)
    remote = distributed.render(scene, camera, mode="ao", spp=3, samples=2, aovs=aovs, address=cluster.address)
    assert list(remote) == list(local) == ["color", *aovs]
    for name in local:
        assert np.array_equal(bits(remote[name]), bits(local[name])), name


def _render_processes():
    """Pids of Ray workers running a lumiere task (Ray titles them ray::<function>)."""
    pids = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/cmdline", "rb") as file:
                    if file.read().startswith(b"ray::_render_range"):
                        pids.append(int(entry))
            except OSError:
                pass
    return pids


def _kill_a_rendering_worker(killed, after):
    """Kills (SIGKILL) the first worker seen running a lumiere task, ``after`` seconds later if it
    still runs one, within a minute; its pid goes to ``killed``."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not killed:
        for pid in _render_processes():
            time.sleep(after)
            if pid in _render_processes():
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
            break
        time.sleep(0.05)


def test_a_worker_killed_mid_task_changes_nothing(cluster):
    scene = lumiere.builtin()
    options = dict(spp=96, size=(96, 72), seed=2)
    local = lumiere.render(scene, **options)
    killed = []
    killer = threading.Thread(target=_kill_a_rendering_worker, args=(killed, 0))
    killer.start()
    result = distributed.render_full(scene, address=cluster.address, tasks=4, max_retries=3, **options)
    killer.join()
    assert killed, "a worker was running a task and was killed"
    assert np.array_equal(bits(result.image), bits(local))


def test_the_merged_checkpoint_resumes_in_the_cli(cluster, cli, tmp_path):
    checkpoint = tmp_path / "merged.ckpt"
    scene = lumiere.builtin()
    distributed.render(scene, spp=3, size=(32, 24), address=cluster.address, checkpoint=str(checkpoint))
    # Continued to 6 spp by the CLI, then by the distributed driver: both equal a straight render.
    cli("render", "--size", "32x24", "--spp", "6", "--checkpoint", tmp_path / "cli.ckpt", "--resume", checkpoint,
        "-o", tmp_path / "resumed.pfm")
    straight = lumiere.render(scene, spp=6, size=(32, 24))
    assert np.array_equal(bits(read_pfm(tmp_path / "resumed.pfm")), bits(straight))
    resumed = distributed.render(scene, spp=6, size=(32, 24), address=cluster.address, checkpoint=str(checkpoint), resume=True)
    assert np.array_equal(bits(resumed), bits(straight))
    with pytest.raises(lumiere.LumiereError, match="seed"):
        distributed.render(scene, spp=8, seed=1, size=(32, 24), address=cluster.address, checkpoint=str(checkpoint), resume=True)


def test_no_task_holds_more_than_its_bytes_of_passes(cluster, monkeypatch):
    scene = lumiere.builtin()
    local = lumiere.render(scene, spp=10, size=(32, 24), seed=3)
    # Three passes of 32x24 per task at most: one task asked for, four given.
    monkeypatch.setattr(distributed, "TASK_BYTES", 12 * 32 * 24 * 3)
    result = distributed.render_full(scene, spp=10, size=(32, 24), seed=3, address=cluster.address, tasks=1)
    assert [task["passes"] for task in result.stats["tasks"]] == [2, 3, 2, 3]
    assert np.array_equal(bits(result.image), bits(local))


def test_checkpoints_hold_the_seconds_so_far_and_replace_a_film_only_with_a_larger_one(cluster, tmp_path, monkeypatch):
    checkpoint = tmp_path / "render.ckpt"
    scene = lumiere.builtin()
    distributed.render(scene, spp=2, size=(32, 24), address=cluster.address, checkpoint=str(checkpoint))
    assert checkpoint_header(checkpoint)[0] == 2
    # A new render over it, saving as often as it may, stopped halfway: the file is only ever
    # replaced by a film with samples (it was rewritten with an empty one while the first task ran),
    # and it holds the seconds rendered so far (it held those of earlier sessions only: 0 here).
    monkeypatch.setattr(distributed, "WAIT_SECONDS", 0.001)
    seen = []

    class Stop(Exception):
        pass

    def progress(done, total):
        seen.append(checkpoint_header(checkpoint)[0])
        if done * 2 >= total:
            raise Stop

    with pytest.raises(Stop):
        distributed.render(scene, spp=8, size=(32, 24), address=cluster.address, tasks=8, checkpoint=str(checkpoint),
                           checkpoint_every=0, progress=progress)
    assert seen and 0 not in seen, seen
    samples, seconds = checkpoint_header(checkpoint)
    assert samples >= 4 and seconds > 0


def test_an_abandoned_render_frees_the_cluster(cluster):
    # Four tasks of 4,000 passes of 100,000 AO rays per pixel (over a minute a task), abandoned as
    # soon as two run: were they not to stop, the render after it would wait minutes for a CPU.
    class Stop(Exception):
        pass

    def progress(done, total):
        if len(_render_processes()) >= 2:
            raise Stop

    scene = lumiere.builtin()
    with pytest.raises(Stop):
        distributed.render(scene, mode="ao", samples=100_000, spp=16_000, size=(8, 6), address=cluster.address,
                           tasks=4, progress=progress)
    start = time.monotonic()
    local = lumiere.render(scene, spp=2, size=(8, 6))
    assert np.array_equal(bits(distributed.render(scene, spp=2, size=(8, 6), address=cluster.address, tasks=2)), bits(local))
    # A task stops within ABANDON_POLL_SECONDS of the driver giving up, or as soon as it starts.
    assert time.monotonic() - start < 30
    # A worker retitles itself idle just after it returns its result.
    deadline = time.monotonic() + 5
    while _render_processes() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _render_processes()


def test_a_scene_file_a_worker_cannot_read_is_named(cluster, tmp_path):
    obj = tmp_path / "gone.obj"
    obj.write_text("v -1 0 -1\nv 1 0 -1\nv 1 0 1\nf 1 3 2\n")
    scene = lumiere.load(obj)
    obj.unlink()
    camera = lumiere.Camera.look_at((0, 1, 4), (0, 0, 0), size=(8, 6))
    with pytest.raises(lumiere.LumiereError, match=f"the worker on .* could not load the scene: {obj}: No such file"):
        distributed.render(scene, camera, mode="hits", spp=2, address=cluster.address, tasks=2)


def test_a_task_larger_than_every_node_is_refused(cluster):
    # Ray would wait forever for a node with two CPUs.
    with pytest.raises(lumiere.LumiereError, match=r"threads_per_task=2 is more CPUs than any node of the cluster has \(at most 1\)"):
        distributed.render(lumiere.builtin(), spp=2, size=(8, 6), address=cluster.address, threads_per_task=2)


def test_a_worker_of_another_version_or_options_is_refused():
    scene = lumiere.builtin()
    camera = lumiere.Camera.builtin((8, 6))
    ours = lumiere._render._options("path", 2, 0, None, None, None, {}).describe(camera._native)
    result = {"host": "node7", "version": lumiere.__version__, "fingerprint": scene.fingerprint, "options": ours}
    distributed._check_result(result, scene, ours)
    with pytest.raises(lumiere.LumiereError, match="the worker on node7 runs lumiere 0.0.1, this process"):
        distributed._check_result(result | {"version": "0.0.1"}, scene, ours)
    other = lumiere._render._options("path", 2, 1, None, None, None, {}).describe(camera._native)
    with pytest.raises(lumiere.LumiereError, match="the worker on node7 would render another image: its seed differ"):
        distributed._check_result(result | {"options": other}, scene, ours)


def test_a_worker_that_dies_past_its_retries_is_a_task_failure(cluster):
    killed = []
    # Well inside its task: Ray reruns a task whose worker died before it began, whatever
    # max_retries says.
    killer = threading.Thread(target=_kill_a_rendering_worker, args=(killed, 0.3))
    killer.start()
    with pytest.raises(distributed.TaskFailed, match=r"the task of passes (0 to 95|96 to 191) failed: \w+: "):
        distributed.render(lumiere.builtin(), spp=192, size=(96, 72), address=cluster.address, tasks=2, max_retries=0)
    killer.join()
    assert killed


def test_an_edited_scene_file_renders_again_and_a_stale_one_is_named(cluster, tmp_path):
    obj = tmp_path / "box.obj"
    obj.write_text("v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 2 -1\nv 1 2 -1\nv 1 2 1\nf 1 3 2\nf 4 5 6\n")
    camera = lumiere.Camera.look_at((0, 1, 4), (0, 1, 0), size=(16, 12))
    options = dict(mode="hits", spp=2, address=cluster.address, tasks=4)
    scene = lumiere.load(obj)
    assert np.array_equal(bits(distributed.render(scene, camera, **options)), bits(lumiere.render(scene, camera, mode="hits", spp=2)))
    # The workers rebuilt the first version; after an edit and a new load they must load it again.
    obj.write_text(obj.read_text().replace("v 1 2 1", "v 0.5 2 1"))
    edited = lumiere.load(obj)
    assert edited.fingerprint != scene.fingerprint
    local = lumiere.render(edited, camera, mode="hits", spp=2)
    assert np.array_equal(bits(distributed.render(edited, camera, **options)), bits(local))
    # Loaded, then edited before the render: the workers read a scene the driver does not have.
    obj.write_text(obj.read_text().replace("v 0.5 2 1", "v 0.25 2 1"))
    stale = lumiere.load(obj)
    obj.write_text(obj.read_text().replace("v 0.25 2 1", "v 0.125 2 1"))
    with pytest.raises(lumiere.LumiereError, match=f"{obj}: the worker on .* changed after lumiere.load read it here"):
        distributed.render(stale, camera, **options)


def test_the_command_line_writes_the_cli_bytes(cluster, cli, tmp_path):
    ao = ["--size", "40x30", "--spp", "4", "--mode", "ao", "--samples", "2"]
    # A PNG of the path tracer with the tone mapping that is not its default.
    path = ["--size", "40x30", "--spp", "4", "--mode", "path", "--tonemap", "clamp", "--exposure", "1"]
    aovs = ["--size", "40x30", "--spp", "2", "--mode", "path", "--aov", "normal,depth,albedo"]
    for args, name in ((ao, "ao.pfm"), (path, "path.png"), (aovs, "aovs.exr")):
        cli("render", *args, "-o", tmp_path / f"cli-{name}")
        command = [sys.executable, "-m", "lumiere.distributed", "render", *args, "--address", cluster.address,
                   "-o", str(tmp_path / f"ray-{name}")]
        subprocess.run(command, check=True, capture_output=True, timeout=120)
        assert (tmp_path / f"ray-{name}").read_bytes() == (tmp_path / f"cli-{name}").read_bytes(), name


def test_the_command_line_denoises_as_the_cli_does(cluster, cli, tmp_path, monkeypatch):
    optional("pyoidn", "pip install pyoidn")
    # The CLI loads OIDN from the pyoidn that `python3` imports: this interpreter's.
    monkeypatch.setenv("PATH", os.path.dirname(sys.executable) + os.pathsep + os.environ["PATH"])
    # The EXR holds the denoised image, the depth AOV and the noisy image.
    for extra, name in ((["--aov", "depth"], "x.exr"), ([], "x.png")):
        args = ["--size", "40x30", "--spp", "4", "--denoise", *extra]
        cli("render", *args, "-o", tmp_path / f"cli-{name}")
        command = [sys.executable, "-m", "lumiere.distributed", "render", *args, "--address", cluster.address,
                   "-o", str(tmp_path / f"ray-{name}")]
        subprocess.run(command, check=True, capture_output=True, timeout=120)
        assert (tmp_path / f"ray-{name}").read_bytes() == (tmp_path / f"cli-{name}").read_bytes(), name


def test_a_clear_error_when_no_cluster_is_reachable(tmp_path):
    # A port nothing listens on (the process must not be connected already, hence a subprocess).
    command = [sys.executable, "-m", "lumiere.distributed", "render", "--address", "127.0.0.1:9", "--spp", "1",
               "--size", "8x6", "-o", str(tmp_path / "x.pfm")]
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert result.returncode == 2
    assert "no Ray cluster reachable at 127.0.0.1:9" in result.stderr
    assert time.perf_counter() - start < 60
    assert not (tmp_path / "x.pfm").exists()


def test_the_command_line_refuses_its_output_and_camera_before_connecting(tmp_path):
    # Each refusal comes before the (unreachable) cluster is asked for: the render would be lost.
    base = [sys.executable, "-m", "lumiere.distributed", "render", "--address", "127.0.0.1:9", "--size", "8x6"]
    for extra, expected in (
        (["-o", str(tmp_path / "x.jpg")], ".jpg is not an image format"),
        (["-o", str(tmp_path / "missing" / "x.png")], f"the folder {tmp_path / 'missing'} does not exist"),
        (["-o", str(tmp_path / "x.png"), "--exposure", "nan"], "exposure must be between -64 and 64 stops"),
        (["-o", str(tmp_path / "x.png"), "--eye", "0,1,3"], "--eye and --target go together"),
        (["-o", str(tmp_path / "x.png"), "--emission", "light.001=1,1,1", "--emission", "light.001=2,2,2"],
         "--emission 'light.001' is given twice"),
        (["-o", str(tmp_path / "x.png"), "--aov", "albedo"], "x.png: --aov writes extra channels, which only an .exr"),
        (["-o", str(tmp_path / "x.exr"), "--aov", "albedo,colour"], 'unknown AOV "colour"'),
        (["-o", str(tmp_path / "x.exr"), "--aov", "depth,depth"], "aov 'depth' is given twice"),
    ):
        result = subprocess.run(base + extra, capture_output=True, text=True, timeout=120)
        assert result.returncode == 2, result.stderr
        assert expected in result.stderr and "no Ray cluster" not in result.stderr, result.stderr
    assert os.listdir(tmp_path) == []


def test_bad_arguments_are_refused_before_connecting(tmp_path):
    with pytest.raises(lumiere.LumiereError, match="spp must be an integer of at least 1"):
        distributed.render(lumiere.builtin(), spp=0, address="127.0.0.1:9")
    with pytest.raises(lumiere.LumiereError, match="tasks must be an integer of at least 1, got True"):
        distributed.render(lumiere.builtin(), spp=2, tasks=True, address="127.0.0.1:9")
    with pytest.raises(lumiere.LumiereError, match="checkpoint_every must be a finite number of seconds"):
        distributed.render(lumiere.builtin(), spp=2, checkpoint_every=float("nan"), address="127.0.0.1:9")
    # An int beyond a float's range (math.isfinite raised OverflowError on it), and an address
    # that is not text (it raised "argument of type 'int' is not iterable").
    with pytest.raises(lumiere.LumiereError, match="checkpoint_every must be a finite number of seconds"):
        distributed.render(lumiere.builtin(), spp=2, checkpoint_every=2**1100, address="127.0.0.1:9")
    with pytest.raises(TypeError, match="address must be a string"):
        distributed.render(lumiere.builtin(), spp=2, size=(8, 6), address=5)
    # A checkpoint that cannot be written is refused now, not after the render it would hold.
    with pytest.raises(lumiere.LumiereError, match="is a directory"):
        distributed.render(lumiere.builtin(), spp=2, checkpoint=tmp_path, address="127.0.0.1:9")
    faceless = lumiere.Scene.from_arrays(np.zeros((3, 3), np.float32), np.zeros((0, 3), np.int64))
    with pytest.raises(lumiere.LumiereError, match="the scene has no faces"):
        distributed.render(faceless, spp=2, size=(8, 6), address="127.0.0.1:9")
    # A slip of the name must not replace a file that is not a checkpoint.
    (tmp_path / "notes.txt").write_text("a user's notes")
    with pytest.raises(lumiere.LumiereError, match="is not a lumiere checkpoint"):
        distributed.render(lumiere.builtin(), spp=2, checkpoint=tmp_path / "notes.txt", address="127.0.0.1:9")
    assert (tmp_path / "notes.txt").read_text() == "a user's notes"
    with pytest.raises(lumiere.LumiereError, match="tasks must be an integer of at least 1"):
        distributed.render(lumiere.builtin(), spp=2, tasks=0, address="127.0.0.1:9")
    with pytest.raises(lumiere.LumiereError, match="threads_per_task must be at most 1024"):
        distributed.render(lumiere.builtin(), spp=2, threads_per_task=5000, address="127.0.0.1:9")
    # Both were found out only on a cluster (the first once tasks were running), or never.
    with pytest.raises(TypeError, match="progress must be callable"):
        distributed.render(lumiere.builtin(), spp=2, progress=5, address="127.0.0.1:9")
    with pytest.raises(lumiere.LumiereError, match="resume needs the checkpoint"):
        distributed.render(lumiere.builtin(), spp=2, resume=True, address="127.0.0.1:9")
