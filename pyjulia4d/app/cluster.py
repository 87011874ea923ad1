"""Rendering on a Dask cluster (the ``distributed`` package): whole frames of an animation,
or tiles of one large frame, as independent work units.

Hart, Sandin & Kauffman 1989 §7.1 splits one image between 64 processors, each working
out which pixels are its own; Ödegaard & Wennergren §10.1 calls ray tracing
"easily parallelized" and its work-pool over network clients unfinished.  Here the pool
is Dask's: the scheduler hands out units, re-runs on another worker the units of a worker
that dies, and returns every result to the client, which alone writes files.  A unit is a
pure function of its scene (executor.render, ``region`` for a tile): rendered twice it gives
the same bits, so a re-run unit changes nothing.  Each worker is a long-lived process that
keeps its OpenCL context and built programs (render.queue_for, build.program) across the
units it gets: a program is built once per worker, not once per frame (units report the
programs they built: ``UnitInfo.programs_built``).

``workers=0`` renders in this process with no cluster (the same units, run in a loop).
"""
from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import threading
import time
import uuid
import warnings
from dataclasses import dataclass
from typing import Any, Callable, Iterator, Sequence

import numpy as np

from pyjulia4d.pipeline import film
from pyjulia4d.pipeline.backdrop import check_backdrop
from pyjulia4d.pipeline.environment import check_environment
from pyjulia4d.pipeline.workload import OUTPUTS
from pyjulia4d.pipeline.progress import Progress
from pyjulia4d.pipeline.result import RenderResult, add_counts
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError, show
from pyjulia4d.files import process_scratch
from pyjulia4d.resources import module_installed


class ClusterError(ValueError):
    """The cluster could not render a unit (its workers kept dying on it, or it went away);
    a ValueError so that the command line says it in one line."""


@dataclass(frozen=True)
class UnitInfo:
    """What one unit cost and where it ran."""
    worker: str
    pid: int
    device: str
    seconds: float          # the unit on the worker, render and all
    programs_built: int     # OpenCL programs this unit built (0 once the worker has them)


@dataclass(frozen=True)
class EncodedImage:
    """A unit's picture as the bytes of its file (PNG or EXR, output.write_image), encoded on
    the worker: the client only writes them (a 4K PNG takes ~1.7 s to encode here, which
    would bound a whole farm's frame rate if the client did it), and ~1-4 bytes per pixel
    travel instead of the 16 of colour and alpha."""
    data: bytes
    capped: int
    guards: dict


# ---------------------------------------------------------------- on the worker


LOCAL_WORKER = "local"   # the worker name of units rendered in this process (workers=0)


def _worker_name() -> Any:
    try:
        from distributed import get_worker
        return get_worker().name
    except (ImportError, ValueError):
        return LOCAL_WORKER


def worker_device(spec: str | None) -> Any:
    """The device a worker renders on: ``spec`` (the client's --device), else the worker's
    PYJULIA4D_DEVICE, else - on an embedded local cluster with several GPUs - GPU number
    <worker name> (one worker per GPU), else the default choice (devices.select_device)."""
    from pyjulia4d.opencl.devices import device_type, is_simulator, list_devices, select_device

    if spec is not None and not isinstance(spec, str):
        return select_device(spec)   # refuses it in one line
    spec = spec or os.environ.get("PYJULIA4D_DEVICE") or None
    if spec is None:
        name = _worker_name()
        if isinstance(name, int):
            gpus = [d for _, d in list_devices() if device_type(d) == "GPU" and not is_simulator(d)]
            if len(gpus) > 1:
                return gpus[name % len(gpus)]
    return select_device(spec)


def render_unit(scene: Scene, device: str | None = None, outputs=None, region=None,
                force: bool = False, encode: tuple[str, dict] | None = None,
                moments: tuple[Scene, ...] = (), shutter: float = 0.0) -> tuple[Any, UnitInfo]:
    """One work unit: executor.render of ``scene`` (its ``region`` alone for a tile) on the
    worker's device; with ``moments`` (a motion-blurred frame's scenes over a shutter of
    ``shutter`` frames), each of them rendered and their mean kept (pipeline/motion.py).
    Returns the RenderResult - or, with ``encode`` = (".png" or ".exr", header), an
    EncodedImage of it, the header followed by the render's report - and a UnitInfo."""
    from pyjulia4d.opencl import build
    from pyjulia4d.opencl.executor import render

    t0 = time.perf_counter()
    dev = worker_device(device)
    before = build.programs_built()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the client checked the scene and said its warnings
        if moments:
            from pyjulia4d.pipeline.motion import blend

            result = blend([render(m, device=dev, force=force, outputs=outputs, region=region) for m in moments],
                           shutter)
        else:
            result = render(scene, device=dev, force=force, outputs=outputs, region=region)
    built = build.programs_built() - before
    if encode is not None:
        result = _encode(result, *encode)
    info = UnitInfo(worker=str(_worker_name()), pid=os.getpid(), device=dev.name.strip(),
                    seconds=time.perf_counter() - t0, programs_built=built)
    return result, info


def worker_scratch() -> str | None:
    """Where a unit keeps its temporary files: its Dask worker's own folder (under the local
    cluster's, which the command removes however its workers end; on another cluster, where
    Dask clears a dead worker's folder when it next starts one), else the system's (None)."""
    try:
        from distributed import get_worker
        return get_worker().local_directory
    except (ImportError, ValueError):   # not on a worker: rendered in this process
        return None


def _encode(result: Any, suffix: str, header: dict) -> EncodedImage:
    """output.write_image's file, as bytes (written to a private temp folder and read back,
    so that the bytes are exactly what write_image writes).  The folder lies in the worker's
    scratch (worker_scratch): a worker killed while it encodes leaves nothing in the system's
    temporary folder."""
    import tempfile
    from pathlib import Path

    from pyjulia4d.app.output import write_image

    report, _ = result.report()
    with tempfile.TemporaryDirectory(prefix="pyjulia4d-", dir=worker_scratch()) as d:
        path = Path(d) / f"frame{suffix}"
        write_image(path, result, {**header, **report})
        data = path.read_bytes()
    return EncodedImage(data, result.capped, dict(result.guards))


def fit_unit(scene: Scene, device: str | None = None, force: bool = False) -> Scene:
    """render.float "auto" and camera.fit resolved once (executor.resolve_float,
    framing.fit_camera), so that every tile of one frame uses the same precision and camera."""
    from pyjulia4d.pipeline.framing import fit_camera
    from pyjulia4d.opencl.executor import render, resolve_float

    dev = worker_device(device)
    scene = resolve_float(scene, dev)
    if not scene.camera.fit:
        return scene
    fitted, _ = fit_camera(scene, lambda s, outs: render(s, device=dev, force=force, outputs=outs))
    return fitted


# ---------------------------------------------------------------- the cluster


def have_cluster() -> bool:
    """Whether Dask distributed is installed (the ``cluster`` extra)."""
    return module_installed("distributed")


def require_cluster(workers: int | None, scheduler: str | None) -> None:
    """--workers N (N > 0) and --scheduler need Dask distributed: one line saying how to get it."""
    if (scheduler is not None or (workers or 0) > 0) and not have_cluster():
        flag = "--scheduler" if scheduler is not None else "--workers"
        raise SceneError(flag, "needs Dask distributed, which is not installed: pip install "
                               "'pyjulia4d[cluster]' (or --workers 0 to render in this process)")


def default_workers(device: str | None = None) -> int:
    """Workers of the embedded cluster when --workers is not given: one per OpenCL GPU when
    the device chosen is a GPU, else 1 (a CPU device already uses every core); 0 (in this
    process) without Dask distributed installed."""
    from pyjulia4d.opencl.devices import device_type, is_simulator, list_devices, select_device

    if not have_cluster():
        return 0
    dev = select_device(device)
    if device is None and device_type(dev) == "GPU":
        return max(1, sum(1 for _, d in list_devices() if device_type(d) == "GPU" and not is_simulator(d)))
    return 1


def check_device(device: str | None, scheduler: str | None) -> Any:
    """The device workload.check estimates for before any frame renders: this machine's
    (it renders here, on its local cluster), or "GPU" for an existing cluster, whose workers
    check again on their own devices (executor.render does, before any kernel runs)."""
    if scheduler is not None:
        return "GPU"
    from pyjulia4d.opencl.devices import select_device
    return select_device(device)


def check_workers(text: Any) -> int:
    """--workers N: an integer 0 <= N <= 1024 (0: in this process, no cluster); the text of
    one, or the int."""
    if isinstance(text, bool) or not isinstance(text, (int, str)):
        raise SceneError("--workers", f"expected a whole number of workers, got {type(text).__name__}")
    try:
        n = int(str(text).strip())
    except ValueError:
        raise SceneError("--workers", f"expected a whole number of workers, got {show(text)}") from None
    if not 0 <= n <= 1024:
        raise SceneError("--workers", f"must be in [0, 1024], got {n}")
    return n


def check_where(workers: int | None, scheduler: str | None) -> None:
    """--workers (a local cluster) and --scheduler (an existing one) exclude each other."""
    if scheduler is not None and workers is not None:
        raise SceneError("--workers", "give --workers (a local cluster) or --scheduler (an existing "
                                      "one), not both")
    if scheduler is None:
        return
    if not (isinstance(scheduler, str) and "://" in scheduler):
        raise SceneError("--scheduler", f"expected an address such as tcp://HOST:8786, got {show(scheduler)}")
    port = scheduler.rpartition(":")[2]
    if port.isascii() and port.isdigit() and (len(port) > 5 or not 0 < int(port) < 65536):
        # Dask would try such a port for SCHEDULER_TIMEOUT seconds
        raise SceneError("--scheduler", f"{show(scheduler)}: the port must be in [1, 65535], got {show(port, 20)}")


SCHEDULER_TIMEOUT = 10.0   # seconds to reach --scheduler (Dask retries until then); twice that for its greeting


def reach_scheduler(address: str, timeout: float = SCHEDULER_TIMEOUT) -> None:
    """Connect once to the Dask scheduler at ``address`` and read its handshake, before any
    Client is made; SceneError (one line) when the address is malformed, nothing answers,
    or what answers is no Dask scheduler.  A Client whose start fails leaves a half-made
    object behind, whose finalizer waited 20 s at exit and printed a traceback; and a server
    that is no scheduler (an HTTP server) answered with bytes that Dask's reader took for
    the length of a 3 EiB frame (MemoryError).  The probe runs in a thread of its own, with
    its own event loop, so that it works where a loop already runs (a notebook)."""
    from distributed.comm import connect

    async def probe() -> None:
        comm = await asyncio.wait_for(connect(address, timeout=timeout), 2 * timeout)
        await comm.close()

    failed: list[Exception] = []

    def run() -> None:
        try:
            asyncio.run(probe())
        except Exception as e:   # whatever a foreign peer's bytes make of Dask's reader
            failed.append(e)

    thread = threading.Thread(target=run, name="pyjulia4d-scheduler-probe", daemon=True)
    thread.start()
    thread.join(3 * timeout)
    if thread.is_alive():
        failed.append(TimeoutError())
    if not failed:
        return
    e = failed[0]
    if isinstance(e, TimeoutError):
        why = f"no Dask scheduler answered within {2 * timeout:g} s"
    elif isinstance(e, (OSError, ValueError, TypeError)):
        why = " ".join(str(e).split())[:200] or type(e).__name__
    else:
        why = f"what answers there is not a Dask scheduler ({type(e).__name__})"
    raise SceneError("--scheduler", f"cannot connect to {show(address)}: {why}")


SCRATCH_PREFIX = "pyjulia4d-cluster-"   # a local cluster's folder in $TMPDIR (files.process_scratch)


@contextlib.contextmanager
def cluster(workers: int | None = None, scheduler: str | None = None,
            device: str | None = None) -> Iterator[Any]:
    """A dask Client: on the cluster at ``scheduler`` (tcp://HOST:PORT), else on an embedded
    LocalCluster of ``workers`` processes (None: default_workers), one thread each.  Yields
    None for ``workers == 0`` (render in this process)."""
    check_where(workers, scheduler)
    require_cluster(workers, scheduler)
    if scheduler is None and workers is None:
        workers = default_workers(device)
    if scheduler is None and workers == 0:
        yield None
        return
    from distributed import Client, LocalCluster

    if scheduler is not None:
        reach_scheduler(scheduler)
        try:
            client = Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT:g}s", set_as_default=False)
        except (OSError, TimeoutError, ValueError, TypeError) as e:
            raise SceneError("--scheduler", f"cannot connect to {show(scheduler)}: "
                                            f"{' '.join(str(e).split()) or type(e).__name__}") from None
        try:
            yield client
        finally:
            client.close()
        return
    # The scheduler's HTTP server (its health and metrics routes) runs even without a
    # dashboard, on port 8787 unless told: where another cluster held it, Dask warned.  The
    # workers' own log of a failed unit (with its traceback) is left out: the unit's error
    # comes back to the client, which says it in one line.
    # The workers' folders (Dask's scratch, the units' temporary files) in one of the
    # command's own, removed when the cluster closes: a worker killed while it wrote leaves
    # nothing behind (nor, by the next run, a command killed itself: files.process_scratch).
    import shutil

    import dask

    scratch = process_scratch(SCRATCH_PREFIX)
    try:
        with dask.config.set({"temporary-directory": scratch}):   # its lock files and the workers' folders
            lc = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                              dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
            try:
                client = Client(lc, set_as_default=False)
                try:
                    yield client
                finally:
                    client.close()
            finally:
                lc.close()
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


# ---------------------------------------------------------------- frames and tiles


def rendered_where(workers: set) -> str:
    """Where units ran, for a closing line: "in this process" (workers=0), else "on N
    workers"; ``workers`` holds their (worker name, pid) pairs."""
    if {name for name, _ in workers} == {LOCAL_WORKER}:
        return "in this process"
    return f"on {len(workers)} worker{'s' if len(workers) != 1 else ''}"


def render_many(client: Any, units: Sequence[tuple[Any, Scene, dict]],
                on_result: Callable[[Any, Any, UnitInfo], None], device: str | None = None,
                force: bool = False) -> None:
    """Render every unit (tag, scene, render_unit keywords) and call ``on_result(tag,
    result, info)`` in this process as each one comes back (in the order they finish).
    With ``client`` None, in this process, one after the other."""
    if client is None:
        for tag, scene, kw in units:
            result, info = render_unit(scene, device=device, force=force, **kw)
            on_result(tag, result, info)
        return
    from distributed import as_completed

    run = uuid.uuid4().hex[:8]
    futures = {}
    for i, (tag, scene, kw) in enumerate(units):
        # earlier units first; the key names the unit (tag) in the dashboard and in logs
        fut = client.submit(render_unit, scene, device=device, force=force, priority=-i,
                            key=f"pyjulia4d-{run}-{i}-{tag}", pure=False, **kw)
        futures[fut] = tag
    try:
        for fut in as_completed(list(futures), loop=client.loop):
            tag = futures[fut]
            try:
                result, info = fut.result()
            except ValueError:  # the scene's own one-line errors (SceneError, WorkloadError)
                raise
            except Exception as e:  # KilledWorker, a closed connection: the cluster's failure
                if type(e).__module__.split(".")[0] not in ("distributed", "dask", "tornado") and \
                        not isinstance(e, (OSError, TimeoutError)):
                    raise
                msg = " ".join(str(e).split()) or type(e).__name__
                raise ClusterError(f"cluster: unit {tag} failed: {type(e).__name__}: {msg}") from None
            futures.pop(fut)
            fut.release()
            on_result(tag, result, info)
    finally:
        for fut in futures:
            fut.cancel()


def fitted(client: Any, scene: Scene, device: str | None = None, force: bool = False) -> Scene:
    """``scene`` with camera.fit and render.float "auto" resolved once (on the cluster when
    there is one)."""
    if not scene.camera.fit and scene.render.float != "auto":
        return scene
    if client is None:
        return fit_unit(scene, device, force)
    return client.submit(fit_unit, scene, device, force, pure=False).result()




def render_tiled(client: Any, scene: Scene, device: str | None = None, outputs=None,
                 force: bool = False, tile: int | None = None, progress: bool = False):
    """One frame in tiles (plan.make_tiles: ``tile`` x ``tile`` pixels, default plan.TILE)
    spread over the cluster, assembled into one RenderResult equal bit for bit to
    executor.render(scene) (each tile is a ``region`` render).  camera.fit is resolved once
    first, so that every tile sees the same camera."""
    from pyjulia4d.pipeline.plan import TILE, make_tiles
    t0 = time.perf_counter()
    scene = fitted(client, scene, device, force)
    W, H = scene.image.width, scene.image.height
    regions = [(t.x0, t.y0, t.w, t.h) for t in make_tiles(W, H, tile or TILE)]
    parts: dict[tuple, Any] = {}
    infos: list[UnitInfo] = []
    bar = Progress(len(regions), "render", "tile", enabled=progress)   # lines, not a bar, in a log

    def got(region, result, info):
        parts[region] = result
        infos.append(info)
        bar.update(1)

    try:
        render_many(client, [(r, scene, {"outputs": outputs, "region": r}) for r in regions], got,
                    device=device, force=force)
    finally:
        bar.close()
    first = next(iter(parts.values()))
    arrays = {}
    for name in OUTPUTS:   # every array a render can keep (workload.OUTPUTS_TABLE)
        a = getattr(first, name)
        if a is None:
            arrays[name] = None
            continue
        full = np.empty((H, W) + a.shape[2:], a.dtype)
        for (x0, y0, w, h), r in parts.items():
            full[y0:y0 + h, x0:x0 + w] = getattr(r, name)
        arrays[name] = full
    counts: dict[str, int] = {}
    guards: dict[str, int] = {}
    for r in parts.values():
        add_counts(counts, r.counts)
        add_counts(guards, r.guards)
    names = sorted({r.device_name for r in parts.values()})
    where = (f" ({len(regions)} tile{'s' if len(regions) != 1 else ''} "
             f"{rendered_where({(i.worker, i.pid) for i in infos})})")
    # scene: the camera every tile used (camera.fit resolved once), which the header records
    result = RenderResult(**arrays, counts=counts, guards=guards, lanes=first.lanes,
                          march_method=first.march_method,
                          device_name=", ".join(names) + where,
                          kernel_seconds=sum(r.kernel_seconds for r in parts.values()), scene=scene,
                          film=film.join(parts, H, W))
    film.finish(result, scene)   # the denoiser over the joined picture: no tile seams
    result.seconds = time.perf_counter() - t0
    return result, scene


def render_on_cluster(scene: Scene, workers: int | None = None, scheduler: str | None = None,
                      device: str | None = None, outputs=None, force: bool = False,
                      progress: bool = False, tile: int | None = None):
    """``render --workers/--scheduler``: check the scene's work here (workload.check: on this
    machine's device, or as on a GPU for an existing cluster, whose workers check again),
    then render_tiled on the cluster.  Returns the RenderResult."""
    from pyjulia4d.pipeline.workload import check

    check_where(workers, scheduler)
    require_cluster(workers, scheduler)
    film.check_denoiser(scene)
    check_environment(scene)
    check_backdrop(scene)
    check(scene, check_device(device, scheduler), force=force, outputs=outputs)
    with cluster(workers, scheduler, device) as client:
        result, _ = render_tiled(client, scene, device, outputs, force, tile, progress)
    return result
