"""Distributed rendering on Ray, with the bytes of a single-process render.

A render of ``spp`` samples per pixel is ``spp`` passes of one camera sample per pixel. Tasks
render ranges of passes anywhere in the cluster and return each pass's raw samples (float32 RGB
per pixel); the driver adds them to its film strictly in pass order, pass after pass, which are
the very floating-point additions :func:`lumiere.render` makes. So the image (and a checkpoint,
which ``lumiere render --resume`` accepts) has the same bytes whatever the number of workers, the
order tasks finish in, or a worker killed and its task retried. (Summing per-task films instead
would not: floating-point addition is not associative.)

    >>> import lumiere, lumiere.distributed
    >>> image = lumiere.distributed.render(lumiere.builtin(), spp=64, address="auto")

Needs Ray: ``pip install ray``. See docs/DISTRIBUTED.md for measurements.
"""

from __future__ import annotations

import contextlib
import math
import os
import socket
import time
import uuid
from typing import Any, Dict, List, Optional, Sequence, Set, Tuple, Union

import numpy as np

from .. import _lumiere
from .._render import (
    Progress,
    RenderResult,
    _aov_arrays,
    _aov_names,
    _array,
    _camera,
    _check_progress,
    _check_scene,
    _options,
)
from .._scene import Camera, Scene, _integer, _path, _rebuild_camera, _rebuild_scene
from ..errors import LumiereError

__all__ = ["ClusterUnreachable", "TaskFailed", "connect", "render", "render_full", "split_passes"]

#: The most bytes of passes one task holds (12 per pixel and pass): a task keeps its passes until
#: it returns them, so a long render of a large image is split into more tasks than asked for
#: rather than one that exhausts a worker's memory.
TASK_BYTES = 256 << 20

#: How long the driver waits for the next task's passes before it reports progress again (and
#: Python sees a Ctrl-C).
WAIT_SECONDS = 0.5

#: How often a task asks whether its render was given up: the longest a task renders on after an
#: error or a Ctrl-C in the driver (one question a second per task is little for the one actor
#: that answers them all, even on a cluster of thousands of CPUs).
ABANDON_POLL_SECONDS = 1.0


class ClusterUnreachable(ConnectionError):
    """No Ray cluster answers at the address given."""


class TaskFailed(RuntimeError):
    """A task failed on the cluster for a reason other than its inputs: its worker died more often
    than ``max_retries`` allows, or Ray itself failed."""


def _ray() -> Any:
    try:
        import ray
    except ImportError as e:
        raise ImportError("lumiere.distributed needs Ray: pip install ray") from e
    return ray


def _check_reachable(address: str, timeout: float) -> None:
    """Fails fast, with a clear message, where Ray itself would retry for a minute."""
    if address in ("auto", "local") or "://" in address:
        return
    host, _, port = address.rpartition(":")
    try:
        with socket.create_connection((host or "127.0.0.1", int(port)), timeout=timeout):
            pass
    except ValueError:
        raise ClusterUnreachable(f"invalid Ray address {address!r}: expected host:port or 'auto'") from None
    except OSError as e:
        raise ClusterUnreachable(
            f"no Ray cluster reachable at {address}: {e.strerror or e}; start one with `ray start --head` "
            "or pass address=None (`--address local` on the command line) to start a local one"
        ) from None


def connect(address: Optional[str] = "auto", timeout: float = 5.0) -> Any:
    """Connects this process to a Ray cluster (once; later calls reuse the connection) and returns
    the ``ray`` module.

    :param address: ``host:port`` of the head's GCS, ``auto`` (``RAY_ADDRESS`` or the cluster
        ``ray start`` last started on this machine), or None to start a local Ray instance.
    :raises ClusterUnreachable: nothing answers at ``address`` (within ``timeout`` seconds).
    """
    if address is not None and not isinstance(address, str):
        raise TypeError(f"address must be a string ('host:port' or 'auto') or None, got {type(address).__name__}")
    ray = _ray()
    if ray.is_initialized():
        return ray
    if address is None:
        ray.init(include_dashboard=False, logging_level="warning")
        return ray
    _check_reachable(address, timeout)
    try:
        ray.init(address=address, logging_level="warning")
    except ConnectionError as e:
        raise ClusterUnreachable(f"no Ray cluster reachable at {address!r}: {e}") from None
    return ray


def split_passes(first: int, end: int, tasks: int) -> List[Tuple[int, int]]:
    """Passes ``first .. end`` as at most ``tasks`` contiguous ``(first, count)`` ranges of sizes
    differing by at most one."""
    total = end - first
    tasks = max(1, min(tasks, total))
    ranges = []
    for index in range(tasks):
        start = first + index * total // tasks
        stop = first + (index + 1) * total // tasks
        ranges.append((start, stop - start))
    return [r for r in ranges if r[1] > 0]


class _Abandonments:
    """The renders a driver gave up (an error, a Ctrl-C), which their tasks poll so as to stop:
    a Ray actor, one per driver process (:func:`_abandonments`).

    Not ``ray.cancel``: in Ray (2.60 included) cancelling a task at the moment its result arrives
    marks it failed between the two steps of its completion, and the driver process aborts
    ("Tried to complete task that was not pending", task_manager.cc), which took down a test run.
    A task that stops by itself races nothing."""

    def __init__(self) -> None:
        self._abandoned: Set[str] = set()

    def abandon(self, render: str) -> None:
        self._abandoned.add(render)

    def abandoned(self, render: str) -> bool:
        return render in self._abandoned


#: This driver's :class:`_Abandonments` actor, with the Ray job it belongs to.
_abandonments_actor: Optional[Tuple[str, Any]] = None


def _abandonments(ray: Any) -> Any:
    """This driver's :class:`_Abandonments` actor, started by its first render and kept for the
    next ones: an actor per render cost a worker process started and stopped each time (0.26 s a
    render on a 2-core machine). No CPU: it must start on a cluster whose CPUs the tasks hold. A
    node lost takes it along and Ray restarts it elsewhere (with the renders given up
    forgotten, which can only let tasks run on)."""
    global _abandonments_actor
    job = ray.get_runtime_context().get_job_id()
    if _abandonments_actor is None or _abandonments_actor[0] != job:
        actor = ray.remote(_Abandonments).options(num_cpus=0, max_restarts=-1, max_task_retries=-1).remote()
        _abandonments_actor = (job, actor)
    return _abandonments_actor[1]


class _Abandoned(Exception):
    """Raised in a task's progress callback to stop its render once the driver gave it up."""


def _stop_when_abandoned(ray: Any, abandonments: Any, render: str) -> Any:
    """A progress callback for the task's render that raises :class:`_Abandoned` once the driver
    has given up ``render`` (in ``abandonments``). It asks every :data:`ABANDON_POLL_SECONDS` and
    never waits for the answer (a render is not slowed by a busy or starting actor); an actor that
    cannot answer is taken for a render still wanted."""
    question = abandonments.abandoned.remote(render)
    next_question = time.monotonic() + ABANDON_POLL_SECONDS
    actor_gone = False  # no more questions then

    def progress(done: int, total: int) -> None:
        nonlocal question, next_question, actor_gone
        if question is not None and ray.wait([question], timeout=0)[0]:
            try:
                abandoned = ray.get(question)
            except ray.exceptions.RayError:
                abandoned, actor_gone = False, True
            if abandoned:
                raise _Abandoned
            question = None
        if question is None and not actor_gone and time.monotonic() >= next_question:
            question = abandonments.abandoned.remote(render)
            next_question = time.monotonic() + ABANDON_POLL_SECONDS

    return progress


def _render_range(
    scene_recipe: tuple,
    camera_recipe: tuple,
    option_args: Dict[str, Any],
    first: int,
    count: int,
    threads: int,
    abandonments: Any,
    render: str,
) -> Dict[str, Any]:
    """The Ray task: passes ``first .. first + count``, each as ``(sample, float32 array, rays)``;
    ``{"abandoned": True}`` where the driver gave up ``render`` (in ``abandonments``, an
    :class:`_Abandonments`) before the task was done.

    The scene and camera come as their recipes and are rebuilt here, in the task, rather than
    unpickled by Ray while it prepares the task's arguments: a file missing on this node is then
    an error naming the node and the file, not a Ray system error."""
    ray = _ray()
    start, cpu = time.perf_counter(), time.process_time()
    host = socket.gethostname()
    try:
        scene, camera = _rebuild_scene(scene_recipe), _rebuild_camera(camera_recipe)
    except LumiereError as e:
        raise LumiereError(
            f"the worker on {host} could not load the scene: {e} (is every file the render reads "
            "on every node, at the same path?)"
        ) from None
    options = _lumiere.NativeOptions(**option_args)
    progress = _stop_when_abandoned(ray, abandonments, render)
    try:
        passes = _lumiere.render_passes(scene._native, camera._native, options, first, count, threads, progress)
    except _Abandoned:
        # Returned, not raised: nothing reads it, and an error nobody reads is printed by Ray.
        return {"abandoned": True}
    return {
        "first": first,
        "passes": [(sample, np.frombuffer(values, dtype=np.float32), rays) for sample, values, rays in passes],
        "fingerprint": scene.fingerprint,
        # What decides the samples' values besides the scene, and the version that computes them:
        # a driver that checks them needs no trust in the nodes' installs.
        "options": options.describe(camera._native),
        "version": _lumiere.__version__,
        "host": host,
        "pid": os.getpid(),
        "seconds": time.perf_counter() - start,
        # The worker process runs one task at a time: its CPU time is this task's.
        "cpu_seconds": time.process_time() - cpu,
    }


def _check_outputs(outputs: Sequence[Tuple[str, str]], scene: Scene, scene_name: str, camera: Camera, camera_name: str) -> None:
    """Refuses ``outputs`` ((name, path) pairs) that are one file, or that would overwrite a file
    the render reads: the scene file, its material libraries and textures, the orbiter file. These
    are ``lumiere render``'s checks and messages, the files named as the caller names them (the
    Python argument, or the flag)."""
    inputs = [(name, file) for name, file in ((scene_name, scene._file), (camera_name, camera._file)) if file is not None]
    _lumiere.check_outputs(list(outputs), inputs, scene._native)


def _different_scene(scene: Scene, host: str) -> str:
    """Why a worker's scene differs from the driver's, as far as the driver can tell."""
    if scene._file is not None:
        return (
            f"{scene._file}: the worker on {host} read a different scene from this file: it differs on that "
            "node, or it changed after lumiere.load read it here (load it again)"
        )
    made = "the built-in scene" if scene.is_builtin else "the same arrays"
    return f"{scene.name}: the worker on {host} built a different scene from {made} (is the same lumiere version installed on every node?)"


def _check_result(result: Dict[str, Any], scene: Scene, options: str) -> None:
    """Refuses a task's passes when its worker rendered another image than this process would:
    another lumiere version, another scene, or other options or camera (``options`` is this
    process's description of them)."""
    host = result["host"]
    if result["version"] != _lumiere.__version__:
        raise LumiereError(
            f"the worker on {host} runs lumiere {result['version']}, this process {_lumiere.__version__}: "
            "install the same version on every node"
        )
    if result["fingerprint"] != scene.fingerprint:
        raise LumiereError(_different_scene(scene, host))
    if result["options"] != options:
        ours = set(options.splitlines())
        differing = [line.partition(":")[0] for line in result["options"].splitlines() if line not in ours]
        raise LumiereError(
            f"the worker on {host} would render another image: its {', '.join(differing)} differ from this "
            "process's (is another build of lumiere installed on that node?)"
        )


def _check_threads_per_task(ray: Any, threads_per_task: int) -> None:
    """Refuses tasks larger than every node: Ray would wait for such a node forever."""
    largest = max((node["Resources"].get("CPU", 0) for node in ray.nodes() if node["Alive"]), default=0)
    if threads_per_task > largest:
        raise LumiereError(
            f"threads_per_task={threads_per_task} is more CPUs than any node of the cluster has (at most {largest:g})"
        )


def _result(ray: Any, ref: Any, first: int, count: int) -> Dict[str, Any]:
    """The task's result; its own error (a scene a worker cannot read) as it was raised there."""
    try:
        return ray.get(ref)
    except ray.exceptions.RayError as e:
        cause = e.cause if isinstance(e, ray.exceptions.RayTaskError) else e
        if isinstance(cause, LumiereError):
            raise cause from None
        why = (str(cause).splitlines() or [""])[0]
        raise TaskFailed(f"the task of passes {first} to {first + count - 1} failed: {type(cause).__name__}: {why}") from e


def render_full(
    scene: Scene,
    camera: Optional[Camera] = None,
    mode: str = "path",
    spp: int = 64,
    seed: int = 0,
    *,
    sampler: Optional[str] = None,
    size: Optional[Tuple[int, int]] = None,
    address: Optional[str] = "auto",
    tasks: Optional[int] = None,
    threads_per_task: int = 1,
    max_retries: int = 3,
    checkpoint: Optional[str] = None,
    checkpoint_every: float = 60.0,
    resume: bool = False,
    progress: Optional[Progress] = None,
    aovs: Sequence[str] = (),
    **technique_options: Any,
) -> RenderResult:
    """Like :func:`render`, returning the image, the AOVs and the statistics (``tasks``: per task
    its first pass, passes, worker wall and CPU seconds, host and pid; ``seconds``: the driver's
    wall time, AOVs included)."""
    _check_scene(scene)
    aovs = _aov_names(aovs)
    if spp is None:
        raise LumiereError("spp must be given: a distributed render does a fixed number of passes")
    spp = _integer(spp, "spp", 1)
    tasks = None if tasks is None else _integer(tasks, "tasks", 1)
    threads_per_task = _integer(threads_per_task, "threads_per_task", 1)
    max_retries = _integer(max_retries, "max_retries", 0)
    # An int too large for a float (2**1100) is not finite either: `math.isfinite` raised on it.
    if not (isinstance(checkpoint_every, (int, float)) and not isinstance(checkpoint_every, bool)
            and (not isinstance(checkpoint_every, int) or abs(checkpoint_every) < 2**1023)
            and math.isfinite(checkpoint_every) and checkpoint_every >= 0):
        raise LumiereError(f"checkpoint_every must be a finite number of seconds, at least 0, got {checkpoint_every!r}")
    _check_progress(progress)
    if resume and checkpoint is None:
        raise LumiereError("resume needs the checkpoint to resume from")
    if checkpoint is not None:
        checkpoint = _path(checkpoint)
    # Refused here, before connecting, rather than by every worker's thread pool.
    if threads_per_task > 1024:
        raise LumiereError(f"threads_per_task must be at most 1024 (as --threads), got {threads_per_task}")
    options = _options(mode, spp, seed, sampler, None, None, technique_options)
    # What each worker builds its options from: the values `_options` accepted.
    option_args = dict(mode=mode, spp=spp, seed=seed, sampler=sampler, **technique_options)
    camera = _camera(scene, camera, size)
    _lumiere.check_aovs(camera.width, camera.height, list(aovs))
    if checkpoint is not None:
        _check_outputs([("checkpoint", checkpoint)], scene, "scene", camera, "camera")
        # Refused now, not once the render is done and the checkpoint cannot hold it; after the
        # check against the inputs, which names an input that the checkpoint would replace.
        _lumiere.check_checkpoint_output(checkpoint)
    width, height = camera.size
    if resume and os.path.exists(checkpoint):
        film = _lumiere.NativeFilm.load_checkpoint(checkpoint, scene._native, camera._native, options)
    else:
        film = _lumiere.NativeFilm(width, height)
    if film.samples > spp:
        raise LumiereError(f"{checkpoint}: the checkpoint has {film.samples} samples per pixel, more than spp={spp}")
    ray = connect(address)
    _check_threads_per_task(ray, threads_per_task)
    start = time.perf_counter()
    cpus = max(1, int(ray.cluster_resources().get("CPU", 1) // max(1, threads_per_task)))
    # A few tasks per CPU: the last ones to finish keep every worker busy till the end.
    wanted = tasks or 4 * cpus
    passes_per_task = max(1, TASK_BYTES // (12 * width * height))
    ranges = split_passes(film.samples, spp, max(wanted, math.ceil((spp - film.samples) / passes_per_task)))
    task = ray.remote(_render_range).options(num_cpus=threads_per_task, max_retries=max_retries)
    scene_ref, camera_ref = ray.put(scene._recipe), ray.put(camera._recipe)
    abandonments, render = _abandonments(ray), uuid.uuid4().hex
    # By first pass. Results are fetched in pass order, one at a time, so that the driver holds
    # one task's passes at most; the others wait in Ray's object store.
    pending = {
        first: (task.remote(scene_ref, camera_ref, option_args, first, count, threads_per_task, abandonments, render), count)
        for first, count in ranges
    }
    description = options.describe(camera._native)
    records: List[Dict[str, Any]] = []  # in pass order, as merged
    pixels = width * height
    earlier_seconds, saved_samples = film.seconds, film.samples
    last_checkpoint = time.monotonic()

    def save() -> None:
        nonlocal saved_samples, last_checkpoint
        film.seconds = earlier_seconds + (time.perf_counter() - start)
        film.save_checkpoint(checkpoint, scene._native, camera._native, options)
        saved_samples, last_checkpoint = film.samples, time.monotonic()

    try:
        while film.samples < spp:
            ref, count = pending[film.samples]
            if ray.wait([ref], num_returns=1, timeout=WAIT_SECONDS)[0]:
                first = film.samples
                result = _result(ray, ref, first, count)
                _check_result(result, scene, description)
                for sample, values, rays in result["passes"]:
                    film.add_pass(sample, values.tobytes(), rays)
                records.append({k: result[k] for k in ("first", "seconds", "cpu_seconds", "host", "pid")} | {"passes": count})
                del pending[first], result
            if progress is not None:
                progress(film.samples * pixels, spp * pixels)
            # Only a film that has grown: an unchanged one (or an empty one over an older
            # checkpoint) is not written again.
            if checkpoint is not None and film.samples > saved_samples and time.monotonic() - last_checkpoint >= checkpoint_every:
                save()
    except BaseException:
        # The film first: telling the tasks needs the cluster, which may be what failed.
        try:
            if checkpoint is not None and film.samples > saved_samples:
                save()
        finally:
            # The tasks still running stop within ABANDON_POLL_SECONDS, those not yet started
            # as they start. The error being raised is what the caller must see, not this one's.
            with contextlib.suppress(Exception):
                abandonments.abandon.remote(render)
        raise
    if checkpoint is not None:
        save()
    # First hits only, a pass cheap beside the image's: computed here, on every core of this machine.
    buffers = _lumiere.aovs(scene._native, camera._native, options, 0, list(aovs)) if aovs else []
    seconds = time.perf_counter() - start
    stats = {
        "samples": film.samples,
        "rays": film.rays,
        "seconds": seconds,
        "discarded": film.discarded,
        "relative_error": film.relative_error(),
        "tasks": records,
        "cpus": cpus,
    }
    return RenderResult(_array(film.image(), height, width), _aov_arrays(aovs, buffers, height, width), stats)


def render(
    scene: Scene,
    camera: Optional[Camera] = None,
    mode: str = "path",
    spp: int = 64,
    seed: int = 0,
    *,
    sampler: Optional[str] = None,
    size: Optional[Tuple[int, int]] = None,
    address: Optional[str] = "auto",
    tasks: Optional[int] = None,
    threads_per_task: int = 1,
    max_retries: int = 3,
    checkpoint: Optional[str] = None,
    checkpoint_every: float = 60.0,
    resume: bool = False,
    progress: Optional[Progress] = None,
    aovs: Sequence[str] = (),
    **technique_options: Any,
) -> Union[np.ndarray, Dict[str, np.ndarray]]:
    """Renders on a Ray cluster; returns what :func:`lumiere.render` returns for the same scene,
    camera and options (the array, or with ``aovs`` the dict of it and its AOVs), bit for bit.

    :param address: the cluster (see :func:`connect`); None starts a local Ray instance.
    :param tasks: how many tasks to split the passes into (default 4 per CPU of the cluster; more
        where a task's passes would hold more than :data:`TASK_BYTES`).
    :param threads_per_task: CPUs (and threads) each task takes; no more than a node has.
    :param max_retries: times Ray reruns a task whose worker died (the bytes do not change).
    :param checkpoint: a file where the merged film is saved every ``checkpoint_every`` seconds
        (when it has grown), on interruption and at the end, in the CLI's format (``lumiere render --resume`` reads it).
    :param resume: continue from ``checkpoint`` when it exists (same scene and options; more
        ``spp`` is fine); needs ``checkpoint``.
    :param progress: ``progress(done, total)`` in pixel samples, as passes are merged.
    :param aovs: names among ``albedo``, ``normal``, ``depth``, computed on this machine once the
        passes are merged (a pass of first hits, cheap beside the image's).

    Budgets (``time``, ``noise``) are not offered: a distributed render does a fixed number of
    passes. The other parameters are :func:`lumiere.render`'s.
    """
    result = render_full(
        scene,
        camera,
        mode,
        spp,
        seed,
        sampler=sampler,
        size=size,
        address=address,
        tasks=tasks,
        threads_per_task=threads_per_task,
        max_retries=max_retries,
        checkpoint=checkpoint,
        checkpoint_every=checkpoint_every,
        resume=resume,
        progress=progress,
        aovs=aovs,
        **technique_options,
    )
    if not result.aovs and not aovs:
        return result.image
    return {"color": result.image, **result.aovs}
