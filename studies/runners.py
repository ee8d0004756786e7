"""Runners: plug-ins that map a top-level function over arguments, yielding results as they complete.

Each runner is ``runner(function, arguments) -> Iterator[result]``: :func:`sequential` (in this
process), or one bound to a pool that lives for many calls, :func:`process_pool` (spawned
single-thread workers, all cores by default) and :func:`dask_pool` (a Dask cluster or a
LocalCluster); :func:`pool` picks one for the command line options. Results come in completion
order, so the function's result must say which argument it belongs to. Workers run one BLAS
thread each (OMP/OpenBLAS/MKL set to 1); pool workers stop on SIGTERM as on Ctrl-C
(studies.interrupts).
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context
from typing import Any, TypeVar

from rpdrill.studies.interrupts import worker_stops_like_ctrl_c

Arg = TypeVar("Arg")
Result = TypeVar("Result")
Runner = Callable[[Callable[[Arg], Result], Sequence[Arg]], Iterator[Result]]

SINGLE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def sequential(function: Callable[[Arg], Result], arguments: Sequence[Arg]) -> Iterator[Result]:
    """In this process, one after the other."""
    for argument in arguments:
        yield function(argument)


@contextlib.contextmanager
def _environment(values: dict[str, str]) -> Iterator[None]:
    """Set environment variables for child processes started inside the block."""
    saved = {key: os.environ.get(key) for key in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


@contextlib.contextmanager
def process_pool(workers: int | None = None) -> Iterator[Runner[Any, Any]]:
    """A runner bound to one pool of spawned single-thread workers, kept for many calls
    (calibration evaluates many scans; starting workers costs seconds)."""
    workers = workers or os.cpu_count() or 1
    with _environment(SINGLE_THREAD):  # workers start on demand: the setting lasts the pool's life
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"),
                                   initializer=worker_stops_like_ctrl_c)

        def run(function: Callable[[Arg], Result], arguments: Sequence[Arg]) -> Iterator[Result]:
            futures = [pool.submit(function, argument) for argument in arguments]
            try:
                for future in as_completed(futures):
                    yield future.result()
            finally:
                for future in futures:
                    future.cancel()

        try:
            yield run
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


@contextlib.contextmanager
def dask_pool(address: str | None = None, workers: int | None = None) -> Iterator[Runner[Any, Any]]:
    """A runner bound to one Dask client, kept for many calls: a cluster at ``address``
    (``tcp://host:8786``), or a LocalCluster of single-thread workers."""
    from dask.distributed import Client, LocalCluster
    from dask.distributed import as_completed as dask_completed

    with contextlib.ExitStack() as stack:
        if address:
            client = stack.enter_context(Client(address))
        else:
            cluster = stack.enter_context(LocalCluster(
                n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                dashboard_address=":0", silence_logs=logging.ERROR, env=SINGLE_THREAD))
            client = stack.enter_context(Client(cluster))

        def run(function: Callable[[Arg], Result], arguments: Sequence[Arg]) -> Iterator[Result]:
            futures = client.map(function, list(arguments), pure=False)
            try:
                for future in dask_completed(futures):
                    yield future.result()
            finally:
                client.cancel(futures)

        yield run


@contextlib.contextmanager
def pool(dask_address: str | None, workers: int | None) -> Iterator[tuple[str, Runner[Any, Any]]]:
    """A runner kept for many calls, for the command line options: its description and the callable
    (``--workers 1``: in this process; ``--dask [ADDRESS]``: Dask; otherwise a process pool)."""
    if dask_address is not None:
        with dask_pool(dask_address or None, workers) as run:
            yield f"dask ({dask_address or 'LocalCluster'})", run
    elif workers == 1:
        yield "sequential", sequential
    else:
        with process_pool(workers) as run:
            yield f"processes ({workers or os.cpu_count()} workers)", run
