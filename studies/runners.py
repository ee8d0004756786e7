"""Runners: plug-ins that map a top-level function over arguments in batches, yielding each batch's
results as it completes.

Each runner is ``runner(function, arguments) -> Iterator[list[result]]``: :func:`sequential` (in this
process, one argument per batch), or one bound to a pool that lives for many calls,
:func:`process_pool` (local worker processes, all cores by default) and :func:`dask_pool` (a Dask
cluster or a LocalCluster); :func:`pool` picks one for the command line options. A pool's workers
start and import rpdrill once (a process pool's with its first call, so that a study refused before
it runs starts none) and take batches of arguments (:func:`batches`): a run pays the process
machinery once per pool and once per batch, not per argument. Results come in completion order, so
the function's result must say which argument it belongs to. Workers run one BLAS thread each and
keep freed memory (WORKER_ENVIRONMENT); process-pool workers are forked from a fork server that
imported and loaded all of it once (the command's module and studies.warm_worker; on Linux: spawned
elsewhere, each loading it), and stop on SIGTERM as on Ctrl-C (studies.interrupts). A worker's
warnings come back with its batch and are issued again in this process (its filters and formatting
apply; each distinct warning once per pool), so that workers print nothing themselves.
"""
from __future__ import annotations

import contextlib
import itertools
import logging
import math
import os
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import forkserver, get_all_start_methods, get_context
from multiprocessing.context import BaseContext
from pathlib import Path
from typing import Any, TypeVar

from .interrupts import worker_stops_like_ctrl_c

Arg = TypeVar("Arg")
Result = TypeVar("Result")
Runner = Callable[[Callable[[Arg], Result], Sequence[Arg]], Iterator[list[Result]]]
Caught = list[tuple[str, type[Warning], str, int]]

# A worker's environment: one BLAS thread, and glibc keeping freed memory for reuse (arrays up to 64 MB
# from the heap, kept up to 256 MB): a run's sample arrays, a few MB each, would otherwise be fresh pages
# every time, and on this machine their page faults cost more than an exact solution and half its
# metrics (docs/performance.md).
WORKER_ENVIRONMENT = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                      "MALLOC_MMAP_THRESHOLD_": str(64 << 20), "MALLOC_TRIM_THRESHOLD_": str(256 << 20)}
BATCHES_PER_WORKER = 4  # enough to even out unequal points; few enough that a batch costs ~nothing to send
PAPER_SCENE = Path(__file__).resolve().parent / "scenes" / "paper_base.yaml"

def batches(arguments: Sequence[Arg], workers: int) -> list[list[Arg]]:
    """``arguments`` in order, cut into at most BATCHES_PER_WORKER batches per worker of equal size
    (+-1): each worker takes several, so one slow batch does not leave the others idle."""
    count = min(len(arguments), workers * BATCHES_PER_WORKER)
    if count == 0:
        return []
    size, extra = divmod(len(arguments), count)
    bounds = [i * size + min(i, extra) for i in range(count + 1)]
    return [list(arguments[a:b]) for a, b in itertools.pairwise(bounds)]


def run_batch(task: tuple[Callable[[Arg], Result], list[Arg]]) -> tuple[list[Result], Caught]:
    """Worker: ``function`` over one batch of arguments, and the warnings it issued (text, category,
    file, line)."""
    function, arguments = task
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        results = [function(argument) for argument in arguments]
    return results, [(str(w.message), w.category, w.filename, w.lineno) for w in caught]


def warm_up() -> None:
    """Worker initializer: import the study machinery and both formulations, and load the exact solver's
    compiled kernels from numba's cache (one blow of the shipped paper scene), once per worker."""
    from ..models import exudyn_model  # noqa: F401 - imported for what it loads (Exudyn)
    from ..models.scene import Scene
    from ..models.simulation import prepare
    from .loading import read_yaml
    from .points import run_point  # noqa: F401 - the study machinery

    one_blow = {**read_yaml(PAPER_SCENE), "metrics": {"transient_blows": 0, "block_blows": 1},
                "solver": {"formulation": "exact", "end_time_s": 0.02}}
    prepare(Scene.model_validate(one_blow)).run()


def start_process_worker() -> None:
    """Process-pool worker initializer: SIGTERM stops it as Ctrl-C does (studies.interrupts), then
    :func:`warm_up` (a few milliseconds in a worker forked from the warm fork server)."""
    worker_stops_like_ctrl_c()
    warm_up()


WARM_WORKER = "rpdrill.studies.warm_worker"


def worker_context(preload: Sequence[str] = ()) -> BaseContext:
    """The process pools' start method: on Linux a fork server that imports the ``preload`` modules and
    studies.warm_worker before it forks the first worker, so that each worker starts with everything
    loaded instead of importing and loading it itself (docs/performance.md); spawn elsewhere (macOS
    forbids forking a process that has loaded its system frameworks, which NumPy's BLAS may be;
    Windows has no fork)."""
    if not sys.platform.startswith("linux") or "forkserver" not in get_all_start_methods():
        return get_context("spawn")
    context = get_context("forkserver")
    context.set_forkserver_preload([*preload, WARM_WORKER])  # read once, when the server starts
    return context


def start_worker_server(preload: Sequence[str] = ()) -> None:
    """Start the process pools' fork server now (Linux; nothing elsewhere) with the ``preload`` modules
    (the command's, whose workers' functions they hold) and studies.warm_worker, so that its imports and
    warm-up (about 1.6 s) run while this process does its own; the first pool then forks its workers at
    once. The server is shared by every pool of this process and ends with it."""
    if worker_context(preload).get_start_method() == "forkserver":
        with _environment(WORKER_ENVIRONMENT):  # the server starts inside: its workers inherit the setting
            forkserver.ensure_running()


def sequential(function: Callable[[Arg], Result], arguments: Sequence[Arg]) -> Iterator[list[Result]]:
    """In this process, one after the other (each result its own batch)."""
    return ([function(argument)] for argument in arguments)


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


def _completed(futures: list[Any], as_done: Callable[[list[Any]], Iterator[Any]],
               cancel: Callable[[list[Any]], None], registry: dict[Any, Any]) -> Iterator[list[Any]]:
    """Each future's batch of results as it completes, after issuing its warnings here (``registry``:
    those issued already); the rest cancelled when the caller stops early."""
    try:
        for future in as_done(futures):
            results, caught = future.result()
            for text, category, filename, lineno in caught:
                warnings.warn_explicit(text, category, filename, lineno, registry=registry)
            yield results
    finally:
        cancel(futures)


@contextlib.contextmanager
def process_pool(workers: int | None = None) -> Iterator[Runner[Any, Any]]:
    """A runner bound to one pool of local workers (:func:`worker_context`, WORKER_ENVIRONMENT), kept for
    many calls; every worker starts (warm, :func:`warm_up`) with the first call, none when nothing is run."""
    workers = workers or os.cpu_count() or 1
    executors: list[ProcessPoolExecutor] = []
    registry: dict[Any, Any] = {}

    def run(function: Callable[[Arg], Result], arguments: Sequence[Arg]) -> Iterator[list[Result]]:
        if not executors:
            with _environment(WORKER_ENVIRONMENT):  # the workers start inside: the setting reaches them
                executors.append(ProcessPoolExecutor(max_workers=workers, mp_context=worker_context(),
                                                     initializer=start_process_worker))
                for _ in range(workers):  # a new worker per task pending when submitted: all start now
                    executors[0].submit(math.sqrt, 0.0)
        futures = [executors[0].submit(run_batch, (function, batch)) for batch in batches(arguments, workers)]
        return _completed(futures, as_completed, lambda pending: [f.cancel() for f in pending], registry)

    try:
        yield run
    finally:
        for executor in executors:
            executor.shutdown(wait=True, cancel_futures=True)


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
                dashboard_address=":0", silence_logs=logging.ERROR, env=WORKER_ENVIRONMENT))
            client = stack.enter_context(Client(cluster))
        client.run(warm_up)
        slots = sum(client.nthreads().values()) or 1
        registry: dict[Any, Any] = {}

        def run(function: Callable[[Arg], Result], arguments: Sequence[Arg]) -> Iterator[list[Result]]:
            futures = client.map(run_batch, [(function, batch) for batch in batches(arguments, slots)], pure=False)
            return _completed(futures, dask_completed, client.cancel, registry)

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
