"""Tile-parallel execution (QGIS-free): in-process, a local Dask cluster, or a Dask scheduler.

See :mod:`.executors` for the backends, security and fault tolerance, and
:mod:`.cache` for the content-addressed tile cache.
"""

from .cache import CACHE_FORMAT, Digest, ProcessLRU, TileCache, file_identity
from .executors import (
    EXECUTORS,
    SCHEDULER_ENV,
    Executor,
    InProcessExecutor,
    LocalDaskExecutor,
    SchedulerExecutor,
    current_cancel,
    make_executor,
    parse_memory,
    task_cancelled,
    tile_run,
    tune_worker_malloc,
)

__all__ = [
    "CACHE_FORMAT",
    "EXECUTORS",
    "SCHEDULER_ENV",
    "Digest",
    "Executor",
    "InProcessExecutor",
    "ProcessLRU",
    "LocalDaskExecutor",
    "SchedulerExecutor",
    "TileCache",
    "current_cancel",
    "file_identity",
    "make_executor",
    "parse_memory",
    "task_cancelled",
    "tile_run",
    "tune_worker_malloc",
]
