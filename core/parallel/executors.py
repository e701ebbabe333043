"""Where tile tasks run: in this process, on a local Dask cluster, or on a Dask scheduler.

One small interface, :class:`Executor`: ``map_tiles(fn, tasks, progress)``
runs ``fn`` on every task and returns the results **in task order**. Tasks
of one call must be independent of each other. ``fn`` must be a picklable
top-level function and the tasks plain data (numpy arrays, numbers,
dataclasses) for the Dask backends; ``shared`` (optional) is one object
every call gets as its first argument, shipped to the cluster once per call
rather than with every task.

Backends
--------
:class:`InProcessExecutor` (default)
    Sequential, in this process, in task order; the numba kernels inside a
    task use all cores as before. Nothing is pickled.
:class:`LocalDaskExecutor`
    A ``dask.distributed.LocalCluster`` of worker *processes* listening on
    127.0.0.1 only, one thread per worker, a memory limit per worker and
    ``NUMBA_NUM_THREADS`` = cores / workers so that workers do not
    oversubscribe the cores.
:class:`SchedulerExecutor`
    An existing scheduler by address (``tcp://host:port``, ``tls://...``) or
    scheduler file (``.json``); default the environment variable
    :data:`SCHEDULER_ENV`. TLS: pass a ``distributed.security.Security``
    or configure ``distributed.comm.tls.*`` in Dask's configuration
    (files or ``DASK_DISTRIBUTED__COMM__TLS__...`` variables), which
    ``Client`` reads when no ``security`` is given.

**Security.** A Dask scheduler runs whatever code its clients send, so a
scheduler reachable by others without authentication is a remote code
execution service. The local cluster binds to loopback; a remote scheduler
must use TLS with client certificates (``tls://``). :class:`SchedulerExecutor`
refuses a plain ``tcp://`` address that is not on loopback (use an SSH
tunnel to loopback, or TLS) unless ``TRUORTHO_DASK_ALLOW_INSECURE=1``.

Fault tolerance and cancel
--------------------------
Dask tasks are submitted with ``retries=2``: a task that raised is run again,
and the tasks of a worker that died (killed, out of memory) are rescheduled
on the others by the scheduler; results are identical wherever a task runs.
At most ``2 x`` (worker threads) tasks are in flight, so a cancel (checked
at least twice a second) stops scheduling at once; running futures are
cancelled and :class:`~truortho.core.errors.CancelledError` is raised.

Cache
-----
With a :class:`~.cache.TileCache` and a ``key`` function, a task whose key
is cached is not run; finished tasks are stored as they arrive (in this
process), so a rerun after a crash only computes what is missing.

Memory
------
Workers run one task at a time (one thread each), so a worker needs the
memory of one task plus what it caches (the caller's image cache); the
``memory_limit`` per worker tells the scheduler and the nanny how much that
is (a worker above 95 % is restarted and its task retried elsewhere).
``map_tiles(..., memory=bytes)`` also tells the scheduler what one task
needs, as the Dask *resource* ``MEMORY``: the local cluster's workers declare
their memory limit as ``MEMORY``, so a task is only placed where it fits; on a
scheduler started separately the resource is used only when every worker
declares it (``dask worker --resources MEMORY=8e9``), since a scheduler holds
a task forever when no worker declares a resource it asks for. A task asking
for more than the largest worker declares asks for that worker's amount.
"""

from __future__ import annotations

import contextlib
import math
import os
import uuid
from collections import deque
from collections.abc import Callable, Sequence
from typing import Any, Protocol, runtime_checkable

from ..errors import CancelledError, InputError
from ..progress import Progress, as_progress
from .cache import TileCache

#: Environment variable naming the scheduler of ``executor="scheduler"``.
SCHEDULER_ENV = "TRUORTHO_DASK_SCHEDULER"
#: Set to 1 to allow a plain ``tcp://`` scheduler that is not on loopback.
INSECURE_ENV = "TRUORTHO_DASK_ALLOW_INSECURE"
#: Retries of a failed Dask task.
RETRIES = 2
EXECUTORS = ("inprocess", "local", "scheduler")

_cancel_hook: Callable[[], bool] | None = None


def task_cancelled() -> bool:
    """Inside a task run by :class:`InProcessExecutor`: True when the user cancelled (else False)."""
    return bool(_cancel_hook()) if _cancel_hook is not None else False


def current_cancel() -> Callable[[], bool] | None:
    """The cancel callback of the in-process run executing this task, or None (on a worker)."""
    return _cancel_hook


@runtime_checkable
class Executor(Protocol):
    def map_tiles(
        self,
        fn: Callable,
        tasks: Sequence,
        progress: Progress | None = None,
        *,
        shared: Any = None,
        cache: TileCache | None = None,
        key: Callable[[Any], str] | None = None,
        label: str = "",
        memory: int | None = None,
    ) -> list: ...

    def close(self) -> None: ...


class _Base:
    """The cache and progress bookkeeping shared by the backends."""

    name = "base"

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        return None

    def describe(self) -> str:
        return self.name

    def map_tiles(
        self, fn, tasks, progress=None, *, shared=None, cache=None, key=None, label="", memory=None
    ):
        progress = as_progress(progress)
        n = len(tasks)
        results: list = [None] * n
        done = 0
        prefix = f"{label}: " if label else ""

        def finished(i: int, value) -> None:
            nonlocal done
            results[i] = value
            done += 1
            progress.update(done / max(n, 1), f"{prefix}tile {done}/{n}")

        def materialise(i: int):
            """Task ``i`` and its cache key; None when the cache already holds its result."""
            if progress.cancelled():
                raise CancelledError("cancelled by the user")
            task = tasks[i]
            k = None
            if cache is not None and key is not None:
                k = key(task)
                hit = cache.get(k)
                if hit is not None:
                    finished(i, hit)
                    return None
            return task, k

        def store(i: int, k: str | None, value) -> None:
            if cache is not None and k is not None:
                cache.put(k, value)
            finished(i, value)

        self._run(fn, n, materialise, store, shared, progress, memory)
        return results

    def _run(self, fn, n, materialise, store, shared, progress, memory=None) -> None:
        raise NotImplementedError


class InProcessExecutor(_Base):
    """Tasks in this process, in task order (numba threads inside).

    ``threads`` > 1 runs up to that many tasks of one call at a time in a thread pool (the
    numba kernels release the GIL); only for task functions that are thread-safe. Results are
    still stored in task order, so they do not depend on the threads.
    """

    name = "inprocess"
    threads = 1

    def __init__(self, threads: int = 1) -> None:
        if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
            raise InputError(f"threads: expected a positive integer, got {threads!r}")
        self.threads = threads

    def _run(self, fn, n, materialise, store, shared, progress, memory=None) -> None:
        global _cancel_hook

        def call(task):
            return fn(task) if shared is None else fn(shared, task)

        previous, _cancel_hook = _cancel_hook, progress.cancelled
        try:
            if self.threads > 1 and n > 1:
                self._run_threads(call, n, materialise, store, progress)
                return
            for i in range(n):
                got = materialise(i)
                if got is None:
                    continue
                task, k = got
                value = call(task)
                if progress.cancelled():
                    raise CancelledError("cancelled by the user")
                store(i, k, value)
        finally:
            _cancel_hook = previous

    def _run_threads(self, call, n, materialise, store, progress) -> None:
        """At most 2 x threads tasks in flight (a cancel stops scheduling), stored in task order."""
        from collections import deque
        from concurrent.futures import ThreadPoolExecutor

        inflight: deque = deque()
        nxt = 0
        with ThreadPoolExecutor(max_workers=self.threads) as pool:
            try:
                while nxt < n or inflight:
                    while nxt < n and len(inflight) < 2 * self.threads:
                        got = materialise(nxt)  # raises CancelledError once cancelled
                        if got is not None:
                            inflight.append((nxt, got[1], pool.submit(call, got[0])))
                        nxt += 1
                    if not inflight:
                        continue
                    i, k, f = inflight.popleft()
                    value = f.result()
                    if progress.cancelled():
                        raise CancelledError("cancelled by the user")
                    store(i, k, value)
            except BaseException:
                for _i, _k, f in inflight:
                    f.cancel()
                raise


def _identity(x):
    return x


class _DaskBase(_Base):
    """Submission with a bounded number of tasks in flight, retries, cancel."""

    retries = RETRIES
    poll = 0.5  # seconds between cancel checks while waiting

    client: Any = None

    def _client(self):
        raise NotImplementedError

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
            self.client = None

    def _slots(self, client) -> int:
        threads = sum(client.nthreads().values()) or 1
        return max(2, 2 * threads)

    def _resources(self, client, memory) -> dict | None:
        """``{"MEMORY": bytes}`` when every worker declares MEMORY (module docstring), else None."""
        if not memory:
            return None
        workers = client.scheduler_info().get("workers", {}).values()
        declared = [w.get("resources", {}).get("MEMORY") for w in workers]
        if not declared or any(d is None for d in declared):
            return None
        return {"MEMORY": float(min(int(memory), max(declared)))}

    def _run(self, fn, n, materialise, store, shared, progress, memory=None) -> None:
        from distributed import wait

        client = self._client()
        resources = self._resources(client, memory)
        run = uuid.uuid4().hex[:12]
        shared_f = None
        if shared is not None:
            # a task (not scattered data): if the worker holding it dies, the scheduler recomputes it
            shared_f = client.submit(_identity, shared, key=f"truortho-shared-{run}", pure=False)
        pending = deque(range(n))
        running: dict = {}
        slots = self._slots(client)
        try:
            while pending or running:
                if progress.cancelled():
                    raise CancelledError("cancelled by the user")
                while pending and len(running) < slots:
                    i = pending.popleft()
                    got = materialise(i)
                    if got is None:
                        continue
                    task, k = got
                    args = (task,) if shared_f is None else (shared_f, task)
                    f = client.submit(
                        fn,
                        *args,
                        key=f"truortho-tile-{run}-{i}",
                        retries=self.retries,
                        pure=False,
                        resources=resources,
                    )
                    running[f] = (i, k)
                if not running:
                    continue
                try:
                    finished, _ = wait(list(running), timeout=self.poll, return_when="FIRST_COMPLETED")
                except TimeoutError:
                    continue
                for f in finished:
                    i, k = running.pop(f)
                    value = f.result()  # raises the task's error after its retries
                    f.release()
                    store(i, k, value)
        except BaseException:
            if running:
                client.cancel(list(running), force=True)
            raise
        finally:
            running.clear()
            if shared_f is not None:
                shared_f.release()


def _spawn_python() -> None:
    """Inside QGIS ``sys.executable`` may be the QGIS binary: spawn workers with a Python."""
    import shutil
    import sys

    if "python" in os.path.basename(sys.executable or "").lower():
        return
    from distributed.utils import get_mp_context

    candidates = [os.path.join(sys.exec_prefix, "bin", "python3"), shutil.which("python3") or ""]
    for exe in candidates:
        if exe and os.access(exe, os.X_OK):
            get_mp_context().set_executable(exe)  # type: ignore[attr-defined]
            return


_MALLOC_TUNED = False


def tune_worker_malloc() -> None:
    """On a Dask worker process (once): glibc's trim threshold 256 MiB and mmap threshold 32 MiB.

    Dask starts workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which also switches off glibc's
    adaptive mmap threshold: every large temporary array of a tile is then mapped and unmapped
    again, and the true-ortho tiles ran 1.8x slower than in a plain process (measured: 4.8 s vs
    2.2 s for the same tiles). Called by the tile tasks; does nothing outside a Dask worker (the
    QGIS process keeps its allocator settings) or without glibc.
    """
    global _MALLOC_TUNED
    if _MALLOC_TUNED:
        return
    _MALLOC_TUNED = True
    try:
        from distributed import get_worker

        get_worker()
    except (ImportError, ValueError):
        return
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-1, 256 << 20)  # M_TRIM_THRESHOLD
        libc.mallopt(-3, 32 << 20)  # M_MMAP_THRESHOLD (glibc's largest)
    except (OSError, AttributeError):
        return


def _worker_memory_default(n_workers: int) -> int:
    import psutil

    return int(psutil.virtual_memory().total * 0.8 / max(n_workers, 1))


class LocalDaskExecutor(_DaskBase):
    """A LocalCluster of ``n_workers`` processes on 127.0.0.1, one thread each.

    Parameters
    ----------
    n_workers : int, optional
        Default the number of cores.
    memory_limit : int or str, optional
        Per worker (bytes or ``"4GiB"``); default 80 % of the machine's memory
        divided by the workers.
    numba_threads : int, optional
        ``NUMBA_NUM_THREADS`` of each worker; default ``max(1, cores // n_workers)``.

    The cluster starts on the first :meth:`map_tiles` and stops on :meth:`close`.
    """

    name = "local"

    def __init__(self, n_workers: int | None = None, memory_limit=None, numba_threads: int | None = None):
        cores = os.cpu_count() or 1
        self.n_workers = int(n_workers or cores)
        if self.n_workers < 1:
            raise InputError(f"workers: expected at least 1, got {n_workers!r}")
        self.memory_limit = (
            memory_limit if memory_limit is not None else _worker_memory_default(self.n_workers)
        )
        self.memory_bytes = parse_memory(self.memory_limit)  # checked now; the workers' MEMORY resource
        self.numba_threads = int(numba_threads or max(1, cores // self.n_workers))
        self.cluster = None
        self.client = None

    def _client(self):
        if self.client is None:
            from distributed import Client, LocalCluster

            _spawn_python()
            self.cluster = self._cluster(LocalCluster)
            self.client = Client(self.cluster)
        return self.client

    def _cluster(self, LocalCluster):
        return LocalCluster(
            n_workers=self.n_workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            memory_limit=self.memory_limit,
            dashboard_address=None,
            env={"NUMBA_NUM_THREADS": str(self.numba_threads)},
            resources={"MEMORY": float(self.memory_bytes or _worker_memory_default(self.n_workers))},
        )

    def worker_pids(self) -> dict[str, int]:
        """Process id of every worker (address -> pid)."""
        return dict(self._client().run(os.getpid))

    def describe(self) -> str:
        return f"local Dask cluster, {self.n_workers} worker process(es) on 127.0.0.1"

    def close(self) -> None:
        super().close()
        if self.cluster is not None:
            self.cluster.close()
            self.cluster = None


def _is_loopback(address: str) -> bool:
    import ipaddress
    from urllib.parse import urlsplit

    host = urlsplit(address if "://" in address else f"tcp://{address}").hostname or ""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class SchedulerExecutor(_DaskBase):
    """Tasks on an existing Dask scheduler.

    Parameters
    ----------
    address : str, optional
        ``tcp://host:port``, ``tls://host:port`` or the path of a scheduler
        file (``.json``); default ``$TRUORTHO_DASK_SCHEDULER``.
    security : distributed.security.Security, optional
        TLS settings; default Dask's configuration.
    """

    name = "scheduler"

    def __init__(self, address: str | None = None, security=None, timeout: float = 30.0):
        address = (address or os.environ.get(SCHEDULER_ENV) or "").strip()
        if not address:
            raise InputError(
                f"SCHEDULER_ADDRESS: give the address of a Dask scheduler (or set {SCHEDULER_ENV})"
            )
        self.is_file = address.lower().endswith(".json")
        if self.is_file and not os.path.isfile(address):
            raise InputError(f"SCHEDULER_ADDRESS: the scheduler file {address!r} does not exist")
        if (
            not self.is_file
            and not address.startswith("tls://")
            and not _is_loopback(address)
            and os.environ.get(INSECURE_ENV) != "1"
        ):
            raise InputError(
                f"SCHEDULER_ADDRESS: {address!r} is neither TLS (tls://) nor on this machine; a Dask "
                "scheduler executes any code it is sent and must never be reachable unauthenticated "
                f"(use TLS, or an SSH tunnel to 127.0.0.1; {INSECURE_ENV}=1 overrides)"
            )
        self.address = address
        self.security = security
        self.timeout = float(timeout)
        self.client = None

    def _client(self):
        if self.client is None:
            from distributed import Client

            kw: dict = {"timeout": self.timeout}
            if self.security is not None:
                kw["security"] = self.security
            try:
                if self.is_file:
                    self.client = Client(scheduler_file=self.address, **kw)
                else:
                    self.client = Client(self.address, **kw)
            except OSError as err:
                raise InputError(
                    f"SCHEDULER_ADDRESS: cannot reach the scheduler {self.address}: {err}"
                ) from None
            if not self.client.nthreads():
                try:
                    self.client.wait_for_workers(1, timeout=self.timeout)
                except TimeoutError:
                    self.close()
                    raise InputError(
                        f"SCHEDULER_ADDRESS: the scheduler {self.address} has no workers"
                    ) from None
        return self.client

    def describe(self) -> str:
        return f"Dask scheduler {self.address}"


def make_executor(
    kind: str | None = None,
    address: str | None = None,
    *,
    n_workers: int | None = None,
    memory_limit=None,
    security=None,
) -> InProcessExecutor | LocalDaskExecutor | SchedulerExecutor:
    """An executor by name: ``"inprocess"`` (default), ``"local"`` or ``"scheduler"``."""
    kind = (kind or "inprocess").lower()
    if kind == "inprocess":
        return InProcessExecutor()
    if kind == "local":
        return LocalDaskExecutor(n_workers, memory_limit)
    if kind == "scheduler":
        return SchedulerExecutor(address, security)
    raise InputError(f"EXECUTOR: expected one of {', '.join(EXECUTORS)}, got {kind!r}")


@contextlib.contextmanager
def tile_run(
    executor=None,
    kind: str | None = None,
    address: str | None = None,
    *,
    scratch,
    cache_dir=None,
    n_workers: int | None = None,
    memory_limit=None,
):
    """``(executor, cache)`` of one tiled run, as a context.

    The executor is ``executor`` or, when None, one made by :func:`make_executor` from ``kind``
    and ``address`` (closed at the end). The tile cache is ``cache_dir`` (kept) or the scratch
    folder ``scratch``, removed when the run succeeds or is cancelled and kept after any other
    error, so that a rerun after a crash resumes from its tiles.
    """
    own = executor is None
    if own:
        executor = make_executor(kind, address, n_workers=n_workers, memory_limit=memory_limit)
    cache = TileCache(cache_dir) if cache_dir is not None else TileCache(scratch, remove_when_done=True)
    try:
        yield executor, cache
    except CancelledError:
        cache.finish()
        raise
    else:
        cache.finish()
    finally:
        if own:
            executor.close()


def parse_memory(value) -> int | None:
    """Bytes of ``"4GiB"``, ``"500MB"``, ``2e9`` or None."""
    if value is None or value == "":
        return None
    if isinstance(value, int | float):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"memory: expected a positive size, got {value!r}")
        return int(value)
    from dask.utils import parse_bytes

    try:
        return int(parse_bytes(str(value)))
    except (ValueError, TypeError):
        raise InputError(f"memory: expected a size like '4GiB', got {value!r}") from None
