"""``rpdrill.drill_hole``: a hole drilled over its depth as a library call (``rpdrill hole`` without its printing), and
several holes on one pool with their comparison figure (the command's)."""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..inputs.arguments import check, either, file_problem, instance_problem
from ..runtime.output_files import check_out
from ..runtime.run_options import RunOptions
from .hole_run import RECORD, HoleResult, check_segments, drilled, holes_folders, segments, write_hole
from .hole_spec import Hole, load_hole

HOLE_OPTIONS = ("workers", "dask", "out", "overwrite", "budget", "quiet")  # its run options (rpdrill.RunOptions)


def drill_hole(hole: str | Path, options: RunOptions | None = None, *, allow_code: Sequence[str] | str = (),
               **run: Any) -> HoleResult:
    """Drill a hole over its depth: one steady run per rod count and layer, the time to each depth and the summary.

    Each distinct (rod count, layer) runs its scene once to its steady state (wave rods: the blows run until the
    advance and the energy per blow reaching the rock settle within 1e-6); the rows at every depth read it. With
    ``out`` the call writes what ``rpdrill hole`` writes there (``hole.csv``, ``hole.json``, ``hole.png``, each
    depth's scene in ``scenes/``, each run's record in ``runs/``) and resumes there; without, a scratch folder.

    Parameters
    ----------
    hole : str or pathlib.Path
        A hole file, or a shipped hole's name (``"holes/top_hammer_30m"``).
    options : RunOptions, optional
        ``workers``, ``dask``, ``out``, ``overwrite``, ``budget``, ``quiet``; or these names as keywords.
    allow_code : sequence of str or str, default ()
        The modules of one's own the rig's scene may run (models.definition.own_code).
    **run
        :class:`RunOptions` names.

    Returns
    -------
    HoleResult
        ``rows`` (a pandas table, one row a depth: rods, layer, rate, time to the depth, energies per blow,
        the energy lost in each coupling, the largest stresses and where, efficiencies, regime), ``summary``
        (what hole.json holds), ``out`` and ``runs`` (each run's record by its key).

    Raises
    ------
    InputError
        When the hole file or an option cannot be used, before anything runs.
    BudgetError
        When a run exceeds the budget, before anything runs.

    Examples
    --------
    >>> import rpdrill
    >>> drilled = rpdrill.drill_hole("holes/top_hammer_30m", workers=1)  # doctest: +SKIP
    >>> drilled.summary["total_time_s"] > drilled.summary["drilling_time_s"]  # doctest: +SKIP
    True
    """
    where = "rpdrill.drill_hole"
    check(where, "hole", hole, either(file_problem, instance_problem(Path, "a hole file's path")))
    options = RunOptions.of(where, options, run, HOLE_OPTIONS)
    return drill_holes([load_hole(hole, tuple([allow_code] if isinstance(allow_code, str) else allow_code))],
                       options)[0]


def drill_holes(holes: Sequence[Hole], options: RunOptions, comparison: bool = False) -> list[HoleResult]:
    """Drill ``holes`` on one pool (a folder each below ``options.out`` when there are several), and with
    ``comparison`` their figure ``comparison.png`` in ``options.out``."""
    from ..runtime.pools import pool

    with tempfile.TemporaryDirectory(prefix="rpdrill-hole-") as scratch:
        out = Path(options.out or scratch)
        folders = holes_folders(holes, out)
        for folder in folders:
            check_out(folder, options.overwrite, RECORD)
        planned = [segments(hole) for hole in holes]
        for hole, found in zip(holes, planned, strict=True):  # every hole's runs against the budget first
            check_segments(hole, found, options)
        results = []
        with pool(options.dask, options.workers, "--dask") as (_, runner):
            for hole, found, folder in zip(holes, planned, folders, strict=True):
                result = drilled(hole, found, folder, runner, options)
                if options.out is not None:
                    write_hole(hole, result, folder)
                results.append(result if options.out is not None else
                               HoleResult(result.name, result.rows, result.summary, None, result.runs))
        if comparison and options.out is not None:
            from .hole_figures import plot_hole
            plot_hole(results, holes, out / "comparison.png")
    return results
