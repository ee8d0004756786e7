"""How an analysis of many points runs: one typed value every analysis takes (``rpdrill.RunOptions``), checked
here once.

``workers`` processes (None: one per core; 1: in the caller's process) or a Dask cluster (``dask``: a
scheduler's address, "" a LocalCluster), the ``out`` folder (None: a scratch folder removed afterwards),
``overwrite`` (write into a folder that holds other files, or start a search afresh there), the ``budget``
its runs are checked against before anything runs and ``quiet`` (no progress bar). Every
analysis call takes ``options=RunOptions(...)`` or the same names as keywords
(``rpdrill.run_study(study, workers=2)``), and refuses the ones it has no use for.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..inputs.arguments import (
    boolean_problem,
    check,
    dask_problem,
    folder_problem,
    instance_problem,
    optional,
    workers_problem,
)
from ..inputs.reading import InputError
from .budgets import DEFAULT_BUDGET, Budget

FIELDS = ("workers", "dask", "out", "overwrite", "budget", "quiet")


@dataclass(frozen=True)
class RunOptions:
    """How an analysis runs its points and where it writes; every analysis call takes it (module doc).

    A call takes ``options=RunOptions(...)`` or the same names as keywords (``rpdrill.run_study(study,
    workers=2)``), and refuses the ones it has no use for.

    Parameters
    ----------
    workers : int, optional
        Processes (None: one per core; 1: in the caller's process).
    dask : str, optional
        A Dask scheduler's address, or "" for a LocalCluster, instead of processes.
    out : str or pathlib.Path, optional
        The folder written (None: a scratch folder removed afterwards).
    overwrite : bool, default False
        Write into a folder that holds other files, or start a search afresh there.
    budget : Budget, default Budget()
        What the runs are checked against before anything runs.
    quiet : bool, default True
        No progress bar.

    Raises
    ------
    InputError
        ``RunOptions: <option>: <problem>`` for a value an option does not allow.

    Examples
    --------
    >>> import rpdrill
    >>> rpdrill.RunOptions(workers=2, out="runs/scan").workers
    2
    >>> try:
    ...     rpdrill.RunOptions(workers=0)
    ... except rpdrill.InputError as error:
    ...     print(error)
    RunOptions: workers: 0: must be a whole number of at least 1
    """

    workers: int | None = None
    dask: str | None = None
    out: str | Path | None = None
    overwrite: bool = False
    budget: Budget = DEFAULT_BUDGET
    quiet: bool = True

    def __post_init__(self) -> None:
        self.checked("RunOptions")

    def checked(self, where: str) -> RunOptions:
        """These options, each checked (InputError '<where>: <option>: <problem>')."""
        check(where, "workers", self.workers, optional(workers_problem))
        check(where, "dask", self.dask, dask_problem)
        check(where, "out", self.out, optional(folder_problem))
        check(where, "overwrite", self.overwrite, boolean_problem)
        check(where, "budget", self.budget, instance_problem(Budget, "a rpdrill.Budget"))
        check(where, "quiet", self.quiet, boolean_problem)
        return self

    @property
    def out_path(self) -> Path | None:
        return None if self.out is None else Path(self.out)

    @classmethod
    def of(cls, where: str, options: RunOptions | None, given: Mapping[str, Any],
           takes: Collection[str] = FIELDS) -> RunOptions:
        """The options of a call at ``where``: ``options`` (default: the defaults) with the keywords ``given``
        in their place; InputError naming ``where`` for an option the call does not take (``takes``), a
        value an option does not allow, or ``options`` that is not a RunOptions."""
        check(where, "options", options, instance_problem(cls, "a rpdrill.RunOptions or None", optional=True))
        unknown = [name for name in given if name not in takes]
        if unknown:
            raise InputError(f"{where}: {unknown[0]}: not an option of this call; its options: {', '.join(takes)}")
        base = options or cls()
        unused = [name for name in FIELDS if name not in takes
                  and getattr(base, name) != getattr(cls, name, None)]
        if unused:
            raise InputError(f"{where}: options.{unused[0]}: {getattr(base, unused[0])!r}: this call has no use for "
                             f"it; its options: {', '.join(takes)}")
        try:
            return dataclasses.replace(base, **given).checked(where) if given else base.checked(where)
        except InputError as error:  # the value named as the call's argument, not as RunOptions's
            raise InputError(str(error).replace("RunOptions: ", f"{where}: ", 1)) from None
