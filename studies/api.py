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
from ..models.evaluation.run_status import run_status
from ..models.solvers.cost import Cause
from .inputs.arguments import (
    boolean_problem,
    callable_problem,
    check,
    check_run_options,
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
from .runtime.tables import table_of
from .scan.study import Study, load_study
from .study_runs import run_studies, run_study_files, study_folders

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["InputError", "Result", "load_scene", "load_study", "run_study", "run_study_files", "save_result",
           "simulate", "table_frame"]


def save_result(result: Result, folder: str | Path, animate: bool = False) -> list[Path]:
    """What ``rpdrill simulate`` writes into ``folder`` (made if missing): ``timeseries.csv``,
    ``summary.json``, ``scene.resolved.yaml``, the ``timeseries.png``/``.svg`` figure, the drawing of the
    drill ``drill.png``; ``animate``: ``drill.gif``, the last blows magnified. A scene with extensions is drawn
    (and, from a run with a solution file, animated) as its built Exudyn model, every item of the extensions
    included (studies.drawings.system_drawing). The files written."""
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
                                         "status": run_status(result.raw, result.metrics)[0], "metrics": result.metrics,
                                         "run": {key: value for key, value in result.raw.info.items()
                                                 if key != "solution_file"},  # a scratch file of the run
                                         "provenance": result.provenance})
    write_resolved(folder / "scene.resolved.yaml", result.raw.simulation.resolved_scene())
    written = [folder / "timeseries.csv", folder / "summary.json", folder / "scene.resolved.yaml",
               *plot_timeseries(columns, result.scene, folder / "timeseries.png"),
               draw(result.scene, folder / "drill.png"), *_wave_readings(result, folder)]
    if animate:
        write_animation(_animated(result), folder / "drill.gif")
        written.append(folder / "drill.gif")
    return written


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
    solution = result.raw.info.get("solution_file")
    if not result.scene.extensions or result.formulation != "exudyn" or not solution or not Path(solution).exists():
        return result.raw
    from ..models.solvers.exudyn_model import build_exudyn

    model = build_exudyn(result.scene)
    model.solution_path = Path(solution)
    return model


def simulate(scene: Scene | str | Path, formulation: str | None = None,
             progress: Callable[[float], None] | None = None, budget: Budget | None = DEFAULT_BUDGET,
             solution_file: Path | None = None) -> Result:
    """Run a scene (or a scene file) with its formulation, or ``formulation`` (``exudyn``, ``exact``,
    ``ode``; the scene's options of another formulation dropped). InputError when it cannot run as
    given, BudgetError when one run's steps or memory exceed ``budget`` (None: unchecked), both before
    it starts; models.evaluation.stability.SimulationFailed when the run diverges. ``solution_file``:
    with the Exudyn formulation, Exudyn's coordinates solution file written there during the run
    (for its SolutionViewer: studies.drawings.drill_animation.view_solution). Loads no figure module:
    the caller's matplotlib is left as it is. A scene with ``solver.steady_state: periodic`` gives its
    steady state (models.steady.steady_run.run_scene)."""
    from ..models.steady.steady_run import run_scene

    check("rpdrill.simulate", "formulation", formulation, optional(choice_problem(FORMULATIONS, "formulation")))
    check("rpdrill.simulate", "progress", progress, callable_problem)
    check("rpdrill.simulate", "budget", budget, instance_problem(Budget, "a rpdrill Budget or None", optional=True))
    check("rpdrill.simulate", "solution_file", solution_file, optional(file_problem))
    scene, source = scene_and_source(scene, "rpdrill.simulate")
    if formulation is not None:
        scene = scene.with_solver(formulation)
    simulation = prepare_scene(scene, source)
    if budget is not None:
        budget.check_run(simulation, source, resampled=Cause("solver.output_interval_s",
                                                              scene.solver.output_interval_s))
    raw = run_scene(simulation, progress=progress, solution=None if solution_file is None else Path(solution_file))
    return Result(scene, raw, {"source": source, **simulation.code_records()})


def table_frame(rows: Sequence[dict[str, str]]) -> pd.DataFrame:
    """A results table (rows as read from ``results.csv``: text cells) as the typed DataFrame
    :func:`run_study` returns: numbers as numbers, text (status, error, a rock's name) as text; one row
    a point, in point order, indexed by the point (studies.runtime.tables)."""
    check("rpdrill.table_frame", "rows", rows, rows_problem)
    rows = list(rows)
    return table_of(list(rows[0]) if rows else [], [list(row.values()) for row in rows])


def run_study(study: Study | str | Path, workers: int | None = None, out: str | Path | None = None,
              dask: str | None = None, quiet: bool = True) -> pd.DataFrame:
    """Run a study (or a study file) on ``workers`` processes (default all cores; 1: in this process) or
    a Dask cluster (``dask``: an address, "" a LocalCluster), into ``out`` (results.csv, study.json,
    optima.csv, plots; resumable as the command's) or, without ``out``, a scratch folder that is
    removed after (no plots). The results table as a DataFrame, one row a point."""
    from .runtime.pools import pool

    check("rpdrill.run_study", "study", study, either(file_problem, instance_problem(Study, "a rpdrill Study or a "
                                                                                    "study file's path")))
    check_run_options("rpdrill.run_study", workers, out, dask, quiet)
    if not isinstance(study, Study):
        study = load_study(study)
    with tempfile.TemporaryDirectory(prefix="rpdrill-study-") as scratch:
        folder = study_folders([str(study.source)], str(out or scratch))[0]
        if out is None:  # a scratch folder keeps no plots
            study = dataclasses.replace(study, spec=study.spec.model_copy(update={"plots": []}))
        with pool(dask, workers, "rpdrill.run_study: dask") as runner:
            return run_studies([study], [folder], runner, dask is not None, quiet)[0].table
