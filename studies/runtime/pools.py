"""Runners: plug-ins that map a top-level function over arguments in batches, yielding each batch's
results as it completes.

Each runner is ``runner(function, arguments) -> Iterator[list[result]]``: :func:`sequential` (in this
process, one argument per batch), or one bound to a pool that lives for many calls,
:func:`process_pool` (local worker processes, all cores by default) and :func:`dask_pool` (a Dask
cluster or a LocalCluster); :func:`pool` picks one for the command line options. A pool's workers
start and import rpdrill once (a process pool's with its first call, so that a study refused before
it runs starts none). A process pool's workers take one argument at a time, so that each result
comes back (and is kept: studies.runtime.resumable) as soon as it is finished; on a stop (Ctrl-C,
SIGTERM, an error) the command ends its workers rather than waiting for what they run, and the
workers end with the command however it ends (studies.runtime.interrupts). Dask workers take
batches of arguments (:func:`batches`), which pay the scheduler's cost once per batch. Results come
in completion order, so the function's result must say which argument it belongs to. Workers run one
BLAS thread each (so that two workers on two cores do not run four threads); process-pool workers are
started the standard library's way for the platform (forked from the command's process on Linux,
which has imported what they run). A worker's warnings come back with its results and are issued
again in this process (its filters and formatting apply; each distinct warning once per pool), so
that workers print nothing themselves.
"""
from __future__ import annotations

import contextlib
import gc
import itertools
import logging
import os
import signal
import sys
import threading
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import InvalidStateError, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

from threadpoolctl import threadpool_limits

from ..inputs.arguments import dask_unreachable
from ..inputs.reading import InputError
from .interrupts import WorkerLost, raise_if_stopped, worker_ends_with_its_command

Arg = TypeVar("Arg")
Output = TypeVar("Output")
Runner = Callable[[Callable[[Arg], Output], Sequence[Arg]], Iterator[list[Output]]]
Caught = list[tuple[str, type[Warning], str, int]]

# Child processes a Dask LocalCluster starts: one BLAS thread each (set before they load NumPy).
ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
DASK_CLOSE_S = 1  # a LocalCluster and its client close within this (after a stop: its workers ended first)
DASK_ANSWER_S = 10  # a scheduler that accepts the connection answers within this (Dask's default: 30 s)
BATCHES_PER_WORKER = 4  # enough to even out unequal points; few enough that a batch costs ~nothing to send

def batches(arguments: Sequence[Arg], workers: int) -> list[list[Arg]]:
    """``arguments`` in order, cut into at most BATCHES_PER_WORKER batches per worker of equal size
    (+-1): each worker takes several, so one slow batch does not leave the others idle."""
    count = min(len(arguments), workers * BATCHES_PER_WORKER)
    if count == 0:
        return []
    size, extra = divmod(len(arguments), count)
    bounds = [i * size + min(i, extra) for i in range(count + 1)]
    return [list(arguments[a:b]) for a, b in itertools.pairwise(bounds)]


def run_batch(task: tuple[Callable[[Arg], Output], list[Arg]]) -> tuple[list[Output], Caught]:
    """Worker: ``function`` over one batch of arguments, and the warnings it issued (text, category,
    file, line)."""
    function, arguments = task
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        results = [function(argument) for argument in arguments]
    return results, [(str(w.message), w.category, w.filename, w.lineno) for w in caught]


def start_process_worker() -> None:
    """Process-pool worker initializer: the command's process stops the run (studies.runtime.interrupts),
    so a worker ignores Ctrl-C, ends at SIGTERM and when that process ends, and runs one BLAS thread. What
    it inherited from the command's process (the libraries imported before the fork) is frozen out of its
    garbage collector (``gc.freeze``): the collector neither walks those objects again nor writes to their
    pages (no copy-on-write)."""
    gc.freeze()
    worker_ends_with_its_command()
    threadpool_limits(1)


def sequential(function: Callable[[Arg], Output], arguments: Sequence[Arg]) -> Iterator[list[Output]]:
    """In this process, one after the other (each result its own batch)."""
    return ([function(argument)] for argument in arguments)


class Completed(Iterator[list[Any]]):
    """Each future's batch of results as it completes, after issuing its warnings here (``registry``:
    those issued already); the rest cancelled when the caller stops early (:meth:`close`).
    ``finished_before_stop``: whether results that completed but were not yet handed out when a stop
    came are results (a process pool's workers ignore Ctrl-C: what they finish is whole), given by
    :meth:`finished_now`."""

    def __init__(self, futures: list[Any], as_done: Callable[[list[Any]], Iterator[Any]],
                 cancel: Callable[[list[Any]], None], registry: dict[Any, Any], finished_before_stop: bool) -> None:
        self.futures, self.cancel, self.registry = futures, cancel, registry
        self.finished_before_stop = finished_before_stop
        self.pending = as_done(futures)
        self.given: set[Any] = set()

    def __next__(self) -> list[Any]:
        try:
            future = next(self.pending)
        except StopIteration:
            self.close()
            raise
        except BaseException:
            self.close()
            raise
        self.given.add(future)
        return self._results(future)

    def _results(self, future: Any) -> list[Any]:
        try:
            results, caught = future.result()
        except BrokenProcessPool:  # a worker was killed: by a signal to all (a stop) or alone
            raise_if_stopped()
            raise WorkerLost() from None
        for text, category, filename, lineno in caught:
            warnings.warn_explicit(text, category, filename, lineno, registry=self.registry)
        return results

    def finished_now(self) -> list[list[Any]]:
        """The batches that have completed but were not handed out (none unless ``finished_before_stop``)."""
        if not self.finished_before_stop:
            return []
        done = [f for f in self.futures if f not in self.given and f.done() and not f.cancelled()
                and f.exception() is None]
        self.given.update(done)
        return [f.result()[0] for f in done]

    def close(self) -> None:
        self.cancel(self.futures)

    def __del__(self) -> None:  # as a generator's finally: a caller that stops early leaves nothing queued
        with contextlib.suppress(Exception):
            self.close()


@contextlib.contextmanager
def process_pool(workers: int | None = None) -> Iterator[Runner[Any, Any]]:
    """A runner bound to one pool of local workers, kept for many calls; every worker starts with the
    first call, none when nothing is run. pandas is imported before the workers are forked (0.2 CPU s a
    process), which every worker would otherwise import for its tables and plots: the three paper scans
    (a continuation study starts its pool before its table) 9 % more CPU without it,
    ``python benchmarks/bench_studies.py --base REV``. (matplotlib imported there too saves 3 to 5 % of
    their CPU but adds 0.3 s to the wall time of a ``rpdrill study`` command, the parent importing it
    while the workers wait: not kept.)"""
    workers = workers or os.cpu_count() or 1
    executors: list[ProcessPoolExecutor] = []
    registry: dict[Any, Any] = {}

    def run(function: Callable[[Arg], Output], arguments: Sequence[Arg]) -> Iterator[list[Output]]:
        if not executors:
            import pandas  # noqa: F401 - before the workers are forked: they make tables and plots from pandas
            executors.append(ProcessPoolExecutor(max_workers=workers, initializer=start_process_worker))
        futures = [executors[0].submit(run_batch, (function, [argument])) for argument in arguments]
        return Completed(futures, as_completed, lambda pending: [f.cancel() for f in pending], registry, True)

    stopped = True
    with _cancelled_futures_quiet():
        try:
            yield run
            stopped = False
        finally:
            for executor in executors:
                if stopped:  # an interrupt or an error: the points under way are not waited for
                    _terminate_workers(executor)
                executor.shutdown(wait=True, cancel_futures=True)


@contextlib.contextmanager
def _cancelled_futures_quiet() -> Iterator[None]:
    """While a pool lives: when a stop ends its workers (a Ctrl-C reaches the whole process group), the
    executor's management thread may set an exception on a future the stop already cancelled
    (InvalidStateError, a race inside concurrent.futures); that is the stop itself, not a failure, and
    no traceback is printed for it. Any other exception of a thread reaches the previous hook (what it
    prevents, and that it lets the others through: tests/test_interrupts.py::
    test_the_cancelled_futures_race_of_a_stop_prints_no_traceback; nothing public silences that race)."""
    previous = threading.excepthook

    def hook(args: threading.ExceptHookArgs) -> None:
        if not isinstance(args.exc_value, InvalidStateError):
            previous(args)

    threading.excepthook = hook
    try:
        yield
    finally:
        threading.excepthook = previous


def _terminate_workers(executor: ProcessPoolExecutor) -> None:
    """End the executor's worker processes now (SIGTERM), whatever they run: Python 3.14's
    ``terminate_workers``, before it the executor's own record of its processes (no public way to reach
    them). Without it a stop waits for the points under way: tests/test_interrupts.py::
    test_a_stop_does_not_wait_for_the_points_under_way."""
    terminate = getattr(executor, "terminate_workers", None)  # Python 3.14
    if terminate is not None:
        terminate()
        return
    for process in list((getattr(executor, "_processes", None) or {}).values()):
        with contextlib.suppress(OSError, ValueError):
            process.terminate()


@contextlib.contextmanager
def dask_pool(address: str | None = None, workers: int | None = None, option: str = "--dask") -> Iterator[Runner[Any, Any]]:
    """A runner bound to one Dask client, kept for many calls: a cluster at ``address``
    (``tcp://host:8786``), or a LocalCluster of single-thread workers. InputError naming ``option``
    when no scheduler answers at ``address`` (studies.inputs.arguments.dask_unreachable: at once when the
    connection is refused, after DASK_CONNECT_S when it is not answered; DASK_ANSWER_S for the
    scheduler's own answer)."""
    from dask.distributed import Client, LocalCluster
    from dask.distributed import as_completed as dask_completed

    with contextlib.ExitStack() as stack:
        stack.enter_context(_dask_logs_quiet())
        if address:
            why = dask_unreachable(address)
            if why is None:
                try:
                    client = stack.enter_context(Client(address, timeout=DASK_ANSWER_S))
                except (OSError, TimeoutError) as error:
                    why = f"{address}: no Dask scheduler answers there ({error}); start one (dask scheduler) or give " \
                          "its address"
            if why is not None:
                raise InputError(f"{option}: {why}")
        else:
            import dask

            _forkserver_without_interrupts()
            with dask.config.set({"distributed.worker.multiprocessing-method": "forkserver"}):
                cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                                       dashboard_address=":0", silence_logs=logging.ERROR, env=ONE_THREAD)
            stack.callback(_close_cluster, cluster)
            client = Client(cluster)
            stack.callback(client.close, DASK_CLOSE_S)
        slots = sum(client.nthreads().values()) or 1
        registry: dict[Any, Any] = {}

        def run(function: Callable[[Arg], Output], arguments: Sequence[Arg]) -> Iterator[list[Output]]:
            futures = client.map(run_batch, [(function, batch) for batch in batches(arguments, slots)], pure=False)
            return Completed(futures, dask_completed, client.cancel, registry, False)

        yield run



@contextlib.contextmanager
def _dask_logs_quiet() -> Iterator[None]:
    """Dask's logs in this process at ERROR while a cluster or client of this run lives and closes, the level
    before restored after. A LocalCluster quiets them (``silence_logs``) only until it closes: after a stop
    its scheduler then logged a closed connection at INFO with a traceback, in 1 stop of 3
    (tests/test_interrupts.py::test_a_study_on_a_dask_local_cluster_stops_within_2_s_without_worker_tracebacks)."""
    logger = logging.getLogger("distributed")
    scheduler = logging.getLogger("distributed.scheduler")
    previous = logger.level
    logger.setLevel(logging.ERROR)
    scheduler.addFilter(_gather_of_cancelled_keys_unlogged)
    try:
        yield
    finally:
        scheduler.removeFilter(_gather_of_cancelled_keys_unlogged)
        logger.setLevel(previous)


def _gather_of_cancelled_keys_unlogged(record: logging.LogRecord) -> bool:
    """False for the scheduler's ERROR "Couldn't gather keys: {key: 'forgotten'}": a stop that comes while
    a finished batch's result is being fetched cancels that batch, and the fetch then finds its key
    forgotten (1 stop of 6 printed it, tests/test_interrupts.py::
    test_a_study_on_a_dask_local_cluster_stops_within_2_s_without_worker_tracebacks). A key that is
    still known (a worker lost) is logged."""
    states = record.args if isinstance(record.args, dict) else None
    if str(record.msg).startswith("Couldn't gather keys") and states:
        return not all(state == "forgotten" for state in states.values())
    return True

def _forkserver_without_interrupts() -> None:
    """Start multiprocessing's fork server (if not running) ignoring Ctrl-C, so that the processes it forks
    (a LocalCluster's workers) ignore it from their first instruction: a Ctrl-C of the whole process group
    then reaches the command's process only, which ends them (no worker prints a traceback). The
    disposition is inherited only as 'ignored' (a handler is reset by exec), so this process ignores
    Ctrl-C while the server starts (milliseconds) and takes it again after. The resource tracker it starts
    (a process that cleans up the workers' semaphores) says nothing of those a stop leaves it to clean
    up: its warning filter, given to it as -W, ignores that one warning."""
    import multiprocessing.forkserver

    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    quiet_tracker = "ignore:resource_tracker:UserWarning"
    sys.warnoptions.append(quiet_tracker)
    try:
        multiprocessing.forkserver.ensure_running()
    finally:
        sys.warnoptions.remove(quiet_tracker)
        signal.signal(signal.SIGINT, previous)


def _close_cluster(cluster: Any) -> None:
    """Close a LocalCluster: at once after a stop (its worker processes ended first: what they run is
    not waited for), within DASK_CLOSE_S otherwise."""
    if sys.exc_info()[0] is not None:  # a stop or an error is on its way out
        for nanny in list(getattr(cluster, "workers", {}).values()):
            process = getattr(getattr(nanny, "process", None), "process", None)
            with contextlib.suppress(Exception):
                process.terminate()
    with contextlib.suppress(Exception):
        cluster.close(timeout=DASK_CLOSE_S)


@contextlib.contextmanager
def pool(dask_address: str | None, workers: int | None, option: str = "--dask") -> Iterator[tuple[str, Runner[Any, Any]]]:
    """A runner kept for many calls, for the command line options: its description and the callable
    (``--workers 1``: in this process; ``--dask [ADDRESS]``: Dask; otherwise a process pool);
    ``option`` names the Dask address in a message (:func:`dask_pool`)."""
    if dask_address is not None:
        with dask_pool(dask_address or None, workers, option) as run:
            yield f"dask ({dask_address or 'LocalCluster'})", run
    elif workers == 1:
        yield "sequential", sequential
    else:
        with process_pool(workers) as run:
            yield f"processes ({workers or os.cpu_count()} workers)", run
