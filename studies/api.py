"""The library's public functions (re-exported by ``import rpdrill``): a scene from a file, one run
of it as a :class:`Result`, a study from a file, its points as a pandas table.

The command line is a client of these: ``rpdrill simulate`` is :func:`simulate` then
:meth:`Result.save`, ``rpdrill study`` is :func:`run_study_files`. Every function raises
:class:`InputError` (a ``ValueError``) on bad input before anything runs, with the message the
command line prints.
"""

from __future__ import annotations

import dataclasses
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..models.definition.formulations import FORMULATIONS
from ..models.definition.scene import Scene
from ..models.evaluation.run_result import Result
from ..models.solvers.cost import Cause
from .inputs.arguments import (
    allow_code_problem,
    boolean_problem,
    callable_problem,
    check,
    choice_problem,
    either,
    file_problem,
    folder_problem,
    instance_problem,
    optional,
    rows_problem,
)
from .inputs.reading import InputError, load_scene, prepare_scene, scene_and_source
from .runtime.budgets import DEFAULT_BUDGET, Budget
from .runtime.output_files import check_out, write_columns_csv, write_json, write_resolved
from .runtime.run_options import RunOptions
from .runtime.tables import table_of
from .scan.study import Study, load_study
from .study_runs import STUDY_OPTIONS, run_studies, run_study_files, study_folders

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["InputError", "Result", "load_scene", "load_study", "run_study", "run_study_files", "save_result",
           "simulate", "table_frame"]


def save_result(result: Result, folder: str | Path, animate: bool = False) -> list[Path]:
    """Write what ``rpdrill simulate`` writes into ``folder`` (made if missing).

    The files: ``timeseries.csv``, ``summary.json``, ``scene.resolved.yaml``, the ``timeseries.png`` and
    ``.svg`` figure, the drawing of the drill ``drill.png``; with ``animate`` also ``drill.gif``, the last blows
    magnified. A scene with extensions is drawn (and, from a run with a solution file, animated) as its built
    Exudyn model, every item of the extensions included (studies.drawings.system_drawing).

    Parameters
    ----------
    result : Result
        A run of :func:`simulate`.
    folder : str or pathlib.Path
        Where the files go; files of the same names there are replaced.
    animate : bool, default False
        Also write ``drill.gif``.

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    InputError
        When ``result`` is not a Result or ``folder`` cannot be written, before anything is written.

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": 0.3})
    >>> files = rpdrill.save_result(rpdrill.simulate(scene, formulation="exact"), "out/first_run")
    >>> sorted(path.name for path in files)
    ['drill.png', 'scene.resolved.yaml', 'summary.json', 'timeseries.csv', 'timeseries.png', 'timeseries.svg']
    """
    from .drawings.drill_animation import write_animation  # matplotlib only when saving
    from .drawings.drill_drawing import draw
    from .figures.timeseries_figure import plot_timeseries

    check("rpdrill.save_result", "result", result, instance_problem(Result, "the Result of rpdrill.simulate"))
    check("rpdrill.save_result", "folder", folder, folder_problem)
    check("rpdrill.save_result", "animate", animate, boolean_problem)
    folder = check_out(folder, overwrite=True, option="rpdrill.save_result: folder")
    folder.mkdir(parents=True, exist_ok=True)
    columns = {name: values.to_numpy() for name, values in result.timeseries.items()}
    write_columns_csv(folder / "timeseries.csv", columns)
    write_json(folder / "summary.json", {"scene": result.scene.name, "formulation": result.formulation,
                                         "status": result.status, "metrics": result.metrics,
                                         "run": run_record(result), "provenance": result.provenance})
    write_resolved(folder / "scene.resolved.yaml", result.raw.simulation.resolved_scene())
    written = [folder / "timeseries.csv", folder / "summary.json", folder / "scene.resolved.yaml",
               *plot_timeseries(columns, result.scene, folder / "timeseries.png"),
               draw(result.scene, folder / "drill.png"), *_wave_readings(result, folder)]
    if animate:
        write_animation(_animated(result), folder / "drill.gif")
        written.append(folder / "drill.gif")
    return written


def run_record(result: Result) -> dict[str, Any]:
    """What ``summary.json`` records of how a run went: the solver's record, the steady state, the items of
    one's own an Exudyn model ran with and their energy account, the warnings (docs/api.md)."""
    energy = result.raw.user_energy
    return {"solver": result.solver, "steady_state": result.steady_state, "exudyn_model": result.exudyn_model,
            "energy_account": None if energy is None else {"accounted": energy.accounted, "declared": energy.declared,
                                                           "unaccounted": energy.unaccounted, "note": energy.note},
            "warnings": result.warnings}


def _wave_readings(result: Result, folder: Path) -> list[Path]:
    """A string of wave rods' readings (models.evaluation.wave_readings): ``wave_readings.json``, the stress
    envelope over the window's blows and a figure per gauge."""
    readings = result.raw.wave_readings
    if readings is None:
        return []
    from .figures.wave_figures import plot_envelope, plot_gauge

    write_json(folder / "wave_readings.json", readings.as_dict())
    first = result.scene.metrics.transient_blows
    written = [folder / "wave_readings.json",
               *plot_envelope(readings, result.scene.name, folder / "stress_envelope.png", slice(first, None))]
    for name, gauge in readings.gauges.items():
        written += plot_gauge(gauge, result.scene.name, folder / f"gauge_{name}.png", result.scene.impact.period_s)
    return written


def _animated(result: Result) -> Any:
    """What the animation of a run draws: an Exudyn run of a scene with extensions, from its solution file
    (``simulate(..., solution_file=...)``), as its model rebuilt (every item of the extensions drawn); any
    other run as the drill string of its scene."""
    solution = result.raw.solution_file
    if not result.scene.extensions or result.formulation != "exudyn" or not solution or not Path(solution).exists():
        return result.raw
    from ..models.solvers.exudyn_model import build_exudyn

    model = build_exudyn(result.scene)
    model.solution_path = Path(solution)
    return model


def simulate(scene: Scene | str | Path, formulation: str | None = None,
             progress: Callable[[float], None] | None = None, budget: Budget | None = DEFAULT_BUDGET,
             solution_file: Path | None = None, allow_code: Sequence[str] | str = ()) -> Result:
    """Run a scene with its formulation, or with ``formulation``: one run into a :class:`Result`.

    A scene with ``solver.steady_state: periodic`` gives its steady state (models.runs.scene_run.run). Loads no
    figure module: the caller's matplotlib is left as it is.

    Parameters
    ----------
    scene : Scene, str or pathlib.Path
        The scene, a scene file, or a shipped scene's name (``"paper_base"``; ``rpdrill shipped``).
    formulation : {"exudyn", "exact", "ode"}, optional
        Run with this formulation instead of the scene's (its solver options of another formulation dropped).
    progress : callable, optional
        Called with the simulated time in seconds as the run advances.
    budget : Budget or None, default Budget()
        The steps and memory one run may take, checked before it starts; None: unchecked.
    solution_file : pathlib.Path, optional
        With the Exudyn formulation, Exudyn's coordinates solution file written there during the run (for
        :func:`view_solution`).
    allow_code : sequence of str or str, default ()
        The modules of one's own the scene may run (an extension's function, a rock law named by import path);
        never read from a scene file (models.definition.own_code).

    Returns
    -------
    Result
        The run's metrics, time series and records.

    Raises
    ------
    InputError
        When the scene cannot run as given, before it starts.
    BudgetError
        When the run's steps or memory exceed ``budget``, before it starts.
    SimulationFailed
        When the run diverges, or the user's code fails in it.

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": 0.5})
    >>> result = rpdrill.simulate(scene, formulation="exact")
    >>> result.formulation
    'exact'
    >>> result.metrics["penetration_rate_m_per_s"] > 0
    True
    >>> list(result.timeseries.columns[:3])
    ['time_s', 'pipe_position_m', 'pipe_velocity_m_per_s']
    """
    from ..models.runs.scene_run import run

    check("rpdrill.simulate", "formulation", formulation, optional(choice_problem(FORMULATIONS, "formulation")))
    check("rpdrill.simulate", "progress", progress, callable_problem)
    check("rpdrill.simulate", "budget", budget, instance_problem(Budget, "a rpdrill Budget or None", optional=True))
    check("rpdrill.simulate", "solution_file", solution_file, optional(file_problem))
    scene, source = scene_and_source(scene, "rpdrill.simulate", allow_code)
    if formulation is not None:
        scene = scene.with_solver(formulation)
    simulation = prepare_scene(scene, source)
    if budget is not None:
        budget.check_run(simulation, source, resampled=Cause("solver.output_interval_s",
                                                              scene.solver.output_interval_s))
    return run(simulation, progress, solution_file=None if solution_file is None else Path(solution_file),
               source=source)


def table_frame(rows: Sequence[dict[str, str]]) -> pd.DataFrame:
    """A results table's rows (text cells, as read from ``results.csv``) as the typed DataFrame :func:`run_study` returns.

    Numbers become numbers, text (status, error, a rock's name) stays text; one row a point, in point order,
    indexed by the point (studies.runtime.tables).

    Parameters
    ----------
    rows : sequence of dict of str to str
        The rows, each a mapping of column name to cell text (``csv.DictReader`` gives them).

    Returns
    -------
    pandas.DataFrame
        The typed table.

    Raises
    ------
    InputError
        When ``rows`` is not a sequence of mappings of text.

    Examples
    --------
    >>> import rpdrill
    >>> table = rpdrill.table_frame([{"point": "0", "impact.frequency_hz": "65.0", "status": "ok"}])
    >>> table["impact.frequency_hz"].dtype.kind, table["status"].iloc[0]
    ('f', 'ok')
    """
    check("rpdrill.table_frame", "rows", rows, rows_problem)
    rows = list(rows)
    return table_of(list(rows[0]) if rows else [], [list(row.values()) for row in rows])


def run_study(study: Study | str | Path, options: RunOptions | None = None, *,
              allow_code: Sequence[str] | str = (), **run: Any) -> pd.DataFrame:
    """Run a study's points, on all cores or a Dask cluster, into a pandas table.

    With ``out`` the run writes what ``rpdrill study`` writes there (``results.csv``, ``study.json``,
    ``optima.csv``, plots) and resumes as the command does; without, it runs in a scratch folder that is
    removed after (no plots).

    Parameters
    ----------
    study : Study, str or pathlib.Path
        A study of :func:`load_study`, a study file, or a shipped study's name (``"paper/frequency_scan"``).
    options : RunOptions, optional
        How the points run and where they are written; or its names as keywords (``workers``, ``dask``,
        ``out``, ``budget``, ``quiet``).
    allow_code : sequence of str or str, default ()
        The modules of one's own a study file's scenes may run (a loaded Study keeps what :func:`load_study`
        allowed).
    **run
        :class:`RunOptions` names.

    Returns
    -------
    pandas.DataFrame
        The results table: one row a point, its axis values, metrics and status.

    Raises
    ------
    InputError
        When the study or an option cannot be used, before anything runs.
    BudgetError
        When the study's runs exceed the budget, before anything runs.

    Examples
    --------
    >>> import rpdrill
    >>> study = rpdrill.load_study("paper/frequency_scan", formulation="exact")
    >>> table = rpdrill.run_study(study, workers=1)  # in this process; None: one worker per core
    >>> len(table), list(table["impact.frequency_hz"][:3]), set(table["status"])
    (23, [10.0, 15.0, 20.0], {'ok'})
    """
    from .runtime.pools import pool

    where = "rpdrill.run_study"
    check(where, "study", study, either(file_problem, instance_problem(Study, "a rpdrill Study or a study file's "
                                                                              "path")))
    options = RunOptions.of(where, options, run, STUDY_OPTIONS)
    check(where, "allow_code", allow_code, allow_code_problem)
    if isinstance(study, Study) and allow_code:
        raise InputError(f"{where}: allow_code: a loaded Study's scenes may run what rpdrill.load_study "
                         "allowed them; give allow_code to rpdrill.load_study")
    if not isinstance(study, Study):
        study = load_study(study, budget=options.budget, allow_code=allow_code)
    with tempfile.TemporaryDirectory(prefix="rpdrill-study-") as scratch:
        folder = study_folders([str(study.source)], str(options.out or scratch))[0]
        if options.out is None:  # a scratch folder keeps no plots
            study = dataclasses.replace(study, spec=study.spec.model_copy(update={"plots": []}))
        with pool(options.dask, options.workers, f"{where}: dask") as runner:
            return run_studies([study], [folder], runner, options.dask is not None, options.quiet)[0].table
