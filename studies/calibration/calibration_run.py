"""A calibration as a library call: :func:`calibrate` is ``rpdrill calibrate`` without its printing.

It reads the calibration file (studies.calibration.calibration_spec), searches (studies.calibration.calibration_search:
every evaluation checkpointed in ``out``/evaluations.jsonl as it finishes, a rerun into the same ``out``
replays them and continues) and, with ``out``, writes the report (studies.calibration.calibration_report:
calibrated_scene.yaml, targets.csv, targets.md, pareto.csv, best_curves.csv, calibration.json). Without
``out`` the checkpoint lives in a scratch folder removed after.
"""

from __future__ import annotations

import contextlib
import shutil
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tqdm import tqdm

from ...models.definition.scene import Scene
from ..inputs.arguments import (
    allow_code_problem,
    check,
    either,
    file_problem,
    instance_problem,
)
from ..runtime.budgets import duration
from ..runtime.evaluation_log import CHECKPOINT, EvaluationLog
from ..runtime.output_files import check_out, staged_directory
from ..runtime.pools import pool
from ..runtime.run_options import RunOptions
from .calibration_report import write_report
from .calibration_search import CalibrationEvaluation, FinalScan, search_calibration
from .calibration_spec import Calibration, load_calibration

WHERE = "rpdrill.calibrate"


@dataclass(frozen=True)
class CalibrationResult:
    """A calibration's outcome (:func:`calibrate`).

    Parameters
    ----------
    calibration : Calibration
        The calibration file, loaded.
    records : list of CalibrationEvaluation
        Every recorded evaluation: its parameters, each target's optimum, the objective.
    best : CalibrationEvaluation or None
        The best evaluation (None when every simulation failed, or every run of a target did).
    final : FinalScan or None
        The best set scanned again around its optima.
    session : dict
        What this session cost.
    failed_targets : list of str
        The targets every run of which failed.
    scene : Scene or None
        The calibrated scene.
    out : pathlib.Path or None
        The folder written.

    Attributes
    ----------
    optima_hz : dict of str to float or None
        Each target's main-lobe optimum of the final scan.
    first_error : str
        The first error of a failed target's runs.

    Examples
    --------
    >>> import rpdrill
    >>> fit = rpdrill.calibrate("paper/calibration", out="runs/calibration")  # doctest: +SKIP
    >>> fit.scene.drill_string.bodies["collar"].mass_kg  # doctest: +SKIP
    """

    calibration: Calibration
    records: list[CalibrationEvaluation]
    best: CalibrationEvaluation | None
    final: FinalScan | None
    session: dict[str, Any]
    failed_targets: list[str]
    scene: Scene | None
    out: Path | None

    @property
    def first_error(self) -> str:
        """The first error of a failed target's runs (of any target's when none failed entirely)."""
        failed = [i for i, label in enumerate(self.calibration.labels) if label in self.failed_targets]
        targets = failed or range(len(self.calibration.spec.targets))
        return next((r.targets[i].error for r in self.records for i in targets if r.targets[i].error), "none")

    @property
    def optima_hz(self) -> dict[str, float | None]:
        """Each target's main-lobe optimum of the final scan (empty without a best evaluation)."""
        return {} if self.final is None else {r.label: r.optimum for r in self.final.results}


def calibrate(calibration: Calibration | str | Path, options: RunOptions | None = None, *,
              allow_code: Sequence[str] | str = (), **run: Any) -> CalibrationResult:
    """Fit a calibration file's scene parameters so that frequency scans put their optima where the targets say.

    ``rpdrill calibrate`` as a library call (module doc): a global search (SciPy's differential evolution, a
    whole population's scans at once), every evaluation checkpointed as it finishes, a rerun into the same
    ``out`` replays them and continues; the best set scanned again around its optima. The file's format:
    docs/calibration.md.

    Parameters
    ----------
    calibration : Calibration, str or pathlib.Path
        A calibration file, its loaded Calibration, or a shipped calibration's name (``"paper/calibration"``).
    options : RunOptions, optional
        ``workers``, ``dask``, ``out`` (resumable; a folder holding anything else, or another calibration, is
        refused unless ``overwrite``, which starts afresh there), ``overwrite``, ``budget``, ``quiet``; or these
        names as keywords. Without ``out``, a scratch folder removed after.
    allow_code : sequence of str or str, default ()
        The modules of one's own its scenes may run (models.definition.own_code); never read from the file.
    **run
        :class:`RunOptions` names.

    Returns
    -------
    CalibrationResult
        Every evaluation, the best, its refined scan and the calibrated scene.

    Raises
    ------
    InputError
        When the file or an option cannot be used, before anything runs.
    BudgetError
        When the search's runs exceed the budget, before anything runs.

    Examples
    --------
    >>> import rpdrill
    >>> fit = rpdrill.calibrate("paper/calibration", out="runs/calibration", workers=2)  # doctest: +SKIP
    >>> fit.best.objective, fit.optima_hz, fit.scene  # doctest: +SKIP
    """
    check(WHERE, "calibration", calibration,
          either(file_problem, instance_problem(Calibration, "a calibration file's path or its loaded Calibration")))
    options = RunOptions.of(WHERE, options, run)
    check(WHERE, "allow_code", allow_code, allow_code_problem)
    workers, dask, quiet, overwrite = options.workers, options.dask, options.quiet, options.overwrite
    folder = None if options.out is None else check_out(options.out, overwrite, CHECKPOINT)
    if not isinstance(calibration, Calibration):
        calibration = load_calibration(calibration, options.budget, allow_code)
    spec = calibration.spec
    with tempfile.TemporaryDirectory(prefix="rpdrill-calibration-") as scratch:
        target = folder or Path(scratch) / "calibration"
        new = not target.exists() or all(p.name.startswith(".") for p in target.iterdir())  # (its lock)
        with contextlib.closing(EvaluationLog(target, calibration.identity, calibration.source, CalibrationEvaluation,
                                                   overwrite)) as log, \
                pool(dask, workers) as (label, runner), \
                tqdm(total=calibration.evaluations, desc=spec.name, unit="eval", disable=quiet) as bar:
            print(f"{spec.name}: {len(calibration.names)} parameters, {len(spec.targets)} targets x "
                  f"{len(calibration.frequencies_hz)} frequencies, {len(log.records)} of {calibration.evaluations} "
                  f"evaluations recorded earlier (estimated {duration(calibration.cpu_s)} of CPU for all), on {label}",
                  file=sys.stderr)
            best = [float("inf")]

            def progress(record: CalibrationEvaluation, replayed: bool) -> None:
                best[0] = min(best[0], record.objective)
                bar.update(1)
                bar.set_postfix(best=f"{best[0]:.4g}", replayed="yes" if replayed else "no")

            found = search_calibration(calibration, runner, log, progress, label)
        scene = None if found.best is None else calibration.scene(found.best.parameters)
        if found.best is None and folder is not None and new:  # nothing worth keeping: a rerun would replay failures
            shutil.rmtree(folder)
        elif found.best is not None and folder is not None:
            with staged_directory(folder) as stage:
                write_report(stage, calibration, found, log.checkpoint["sessions"])
    return CalibrationResult(calibration, found.records, found.best, found.final, found.session, found.failed_targets,
                             scene, None if found.best is None else folder)
