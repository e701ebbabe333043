"""Fixtures of the tile-parallel tests: one local Dask cluster and one separately started scheduler
per test session (starting them costs seconds), shared by every module that asks for them."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import pytest


@pytest.fixture(scope="session")
def dask_cluster():
    pytest.importorskip("distributed")
    from truortho.core.parallel import LocalDaskExecutor

    ex = LocalDaskExecutor(n_workers=2, memory_limit="1.5GiB")
    yield ex
    ex.close()


@pytest.fixture(scope="session")
def dask_scheduler_file(tmp_path_factory):
    """``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1, stopped at the end."""
    pytest.importorskip("distributed")
    folder = tmp_path_factory.mktemp("scheduler")
    sfile = folder / "scheduler.json"
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    cli = [sys.executable, "-m", "dask"]
    procs = [
        subprocess.Popen(
            [*cli, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(sfile)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=folder,
        )
    ]  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not sfile.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        assert sfile.exists(), "the scheduler did not start"
        assert json.loads(sfile.read_text())["address"].startswith("tcp://127.0.0.1:")
        for _ in range(2):
            procs.append(
                subprocess.Popen(
                    [*cli, "worker", "--scheduler-file", str(sfile), "--host", "127.0.0.1", "--nthreads", "1",
                     "--nworkers", "1", "--memory-limit", "1.5GiB", "--no-dashboard"],
                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=folder,
                )
            )  # fmt: skip
        yield str(sfile)
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
