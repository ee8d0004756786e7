"""The paper's reproduction as a library call: :func:`reproduce` is ``rpdrill reproduce`` without its
printing (studies.reproduction.paper_reproduction: the file format, the cases, the trends; here, with the
pages it generates, because they are what it makes).

It scans every case of the reproduction file (default ``studies/paper/reproduction.yaml``) on the shipped
scene and its variants, and makes the pages (studies.pages.paper_pages): ``reproduction.md`` (the paper
against rpdrill, the trends, the sub-harmonic lobes), ``parameters.md`` (the shipped scene's values,
the bounds and reasons of the reproduction file's ``calibration`` file, the rock-mode resonances, and
the ``calibration`` run), ``figures.md`` (the paper's figures redrawn), ``sensitivity.md`` when a
``sensitivity`` run is given. With ``out`` it writes them, the figures (``figures/fig<N>.png``/``.svg``),
``cases.csv`` (every curve) and ``reproduction.json`` there; with ``docs`` it also copies the pages and
figures into that folder.
"""

from __future__ import annotations

import importlib.metadata
import shlex
import shutil
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..calibration.calibration_spec import load_calibration
from ..figures.paper_figures import draw_figure
from ..inputs.arguments import (
    allow_code_problem,
    check,
    file_problem,
    folder_problem,
    optional,
)
from ..inputs.reading import InputError
from ..reproduction.paper_reproduction import (
    CaseResult,
    Reproduction,
    load_reproduction,
    scan_cases,
    trend_checks,
    within,
)
from ..runtime.budgets import Budget
from ..runtime.output_files import check_out, staged_directory, write_json, write_rows_csv
from ..runtime.pools import pool
from ..runtime.run_options import RunOptions
from .paper_pages import figures_page, parameters_page, reproduction_page, sensitivity_page, site_prefix

PAPER = Path(__file__).resolve().parents[1] / "paper"
DEFAULT = PAPER / "reproduction.yaml"


@dataclass(frozen=True)
class ReproductionResult:
    """The paper reproduced (:func:`reproduce`).

    Parameters
    ----------
    reproduction : Reproduction
        The reproduction file, loaded.
    by_variant : dict of (str or None) to list of CaseResult
        Every case on the shipped scene (under None) and on each variant: its curves and optimum.
    pages : dict of str to str
        The pages made, file name to Markdown.
    provenance : dict
        What the scans cost, the versions.
    out : pathlib.Path or None
        The folder written.

    Attributes
    ----------
    results : list of CaseResult
        The cases on the shipped scene.
    trends : list of dict
        Whether each trend of the paper holds.
    stated, reached : list of CaseResult
        The cases whose optimum the paper states; of them, those reached within the file's tolerance.
    passed : bool
        Every optimum the paper states reached and every trend holding.

    Examples
    --------
    >>> import rpdrill
    >>> paper = rpdrill.reproduce()  # doctest: +SKIP
    >>> [case.case.label for case in paper.reached]  # doctest: +SKIP
    """

    reproduction: Reproduction
    by_variant: dict[str | None, list[CaseResult]]
    pages: dict[str, str]
    provenance: dict[str, Any]
    out: Path | None

    @property
    def results(self) -> list[CaseResult]:
        """The cases on the shipped scene."""
        return self.by_variant[None]

    @property
    def trends(self) -> list[dict[str, Any]]:
        return trend_checks(self.reproduction, self.results)

    @property
    def stated(self) -> list[CaseResult]:
        """The cases whose optimum the paper states."""
        return [r for r in self.results if r.case.paper.optimum_hz is not None]

    @property
    def reached(self) -> list[CaseResult]:
        """The stated optima reached within the file's tolerance."""
        return [r for r in self.stated if within(r.optimum.optimum, r.case.paper, self.reproduction.spec.tolerance)]

    @property
    def passed(self) -> bool:
        """Every optimum the paper states reached and every trend holding."""
        return len(self.reached) == len(self.stated) and all(t["rises"] for t in self.trends)


def _shown(path: str | Path) -> str:
    """A path as a page shows it: relative to the working folder where it lies below it."""
    path = Path(path)
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def made_by(file: Path, reproduction: Reproduction, out: Path | None, calibration: Path | None,
            sensitivity: Path | None, docs: Path | None) -> str:
    """The command line that makes the pages and the input files it reads, as the pages state them."""
    words = ["rpdrill", "reproduce"]
    if file.resolve() != DEFAULT.resolve():
        words.append(_shown(file))
    for option, value in (("out", out), ("calibration", calibration), ("sensitivity", sensitivity), ("docs", docs)):
        if value is not None:
            words += [f"--{option}", _shown(value)]
    inputs = [_shown(file)]
    if isinstance(reproduction.spec.base_scene, str):
        inputs.append(_shown(file.parent / reproduction.spec.base_scene))
    if reproduction.calibration_file is not None:
        inputs.append(_shown(reproduction.calibration_file))
    if calibration is not None:
        inputs.append(_shown(calibration / "calibration.json"))
    if sensitivity is not None:
        inputs.append(_shown(sensitivity / "summary.json"))
    return f"`{shlex.join(words)}` (inputs: {', '.join(f'`{name}`' for name in inputs)})"


def reproduce(reproduction: str | Path = DEFAULT, calibration: str | Path | None = None,
              sensitivity: str | Path | None = None, docs: str | Path | None = None, options: RunOptions | None = None,
              *, allow_code: Sequence[str] | str = (), **run: Any) -> ReproductionResult:
    """Reproduce the paper on the shipped scene and make its pages: ``rpdrill reproduce`` as a library call.

    Every case of the reproduction file on a 1 Hz grid (exact formulation), on the shipped scene and on each
    variant; its optima against the paper's, the trends, the sub-harmonic lobes, the paper's Figs. 2-6 redrawn
    (module doc). The pages: ``reproduction.md``, ``parameters.md``, ``figures.md``, and ``sensitivity.md`` when a
    sensitivity run is given; their links to other pages of the documentation site are made relative to the site's
    root (the nearest folder at or above ``docs`` holding ``conf.py``).

    Parameters
    ----------
    reproduction : str or pathlib.Path, optional
        The reproduction file (default ``studies/paper/reproduction.yaml``).
    calibration : str or pathlib.Path, optional
        The ``--out`` folder of ``rpdrill calibrate``, for parameters.md.
    sensitivity : str or pathlib.Path, optional
        The ``--out`` folder of ``rpdrill sensitivity``, for sensitivity.md.
    docs : str or pathlib.Path, optional
        Where the pages and figures are also copied (with ``out``).
    options : RunOptions, optional
        ``workers``, ``dask``, ``out`` (new, empty or an earlier reproduction's), ``overwrite`` (any folder); or
        these names as keywords.
    allow_code : sequence of str or str, default ()
        The modules of one's own its scenes may run (models.definition.own_code).
    **run
        :class:`RunOptions` names.

    Returns
    -------
    ReproductionResult
        Every case, the trends, the pages.

    Raises
    ------
    InputError
        When a file, a folder or an option cannot be used, before anything runs.

    Examples
    --------
    >>> import rpdrill
    >>> paper = rpdrill.reproduce(out="runs/reproduction", workers=2)  # doctest: +SKIP
    >>> len(paper.reached), len(paper.stated), paper.passed  # doctest: +SKIP
    """
    where = "rpdrill.reproduce"
    check(where, "reproduction", reproduction, file_problem)
    for name, value in (("calibration", calibration), ("sensitivity", sensitivity), ("docs", docs)):
        check(where, name, value, optional(folder_problem))
    options = RunOptions.of(where, options, run, ("workers", "dask", "out", "overwrite"))
    out, workers, dask, overwrite = options.out, options.workers, options.dask, options.overwrite
    check(where, "allow_code", allow_code, allow_code_problem)
    file = Path(reproduction)
    folder = None if out is None else check_out(out, overwrite, "reproduction.json")
    docs_folder = None if docs is None else check_out(docs, True, option="--docs")
    runs = {option: None if value is None else Path(value) for option, value in
            (("calibration", calibration), ("sensitivity", sensitivity))}
    for option, command in (("calibration", "calibrate"), ("sensitivity", "sensitivity")):
        if runs[option] is not None and not runs[option].is_dir():
            raise InputError(f"--{option}: {runs[option]}: not a folder; give the --out of `rpdrill {command}`")
    loaded = load_reproduction(file, allow_code)
    # only the calibration's bounds and reasons are read (its search is not run): no limit on its CPU estimate
    calibration_file = None if loaded.calibration_file is None else \
        load_calibration(loaded.calibration_file, Budget(accept_long=True), allow_code)
    with pool(dask, workers) as (label, runner):
        print(f"{loaded.spec.name}: {len(loaded.spec.cases)} cases x {len(loaded.frequencies_hz)} "
              f"frequencies on {label}", file=sys.stderr)
        by_variant, cost = scan_cases(loaded, runner)
    results = by_variant[None]
    provenance = {"cases": len(results), **cost, "rpdrill_version": importlib.metadata.version("rpdrill"),
                  "exudyn_version": importlib.metadata.version("exudyn")}
    stated = made_by(file, loaded, folder, runs["calibration"], runs["sensitivity"], docs_folder)
    site = site_prefix(docs_folder)
    pages = {"reproduction.md": reproduction_page(loaded, by_variant, provenance, stated, site,
                                                  sensitivity_here=runs["sensitivity"] is not None),
             "parameters.md": parameters_page(loaded, results, calibration_file, runs["calibration"], stated, site),
             "figures.md": figures_page([(f.number, f.title, f"figures/fig{f.number}.svg") for f in loaded.spec.figures],
                                        stated)}
    tornados = sorted(runs["sensitivity"].glob("tornado_*.svg")) if runs["sensitivity"] is not None else []
    if runs["sensitivity"] is not None:
        pages["sensitivity.md"] = sensitivity_page(runs["sensitivity"], [f"figures/{i.name}" for i in tornados], stated)
    result = ReproductionResult(loaded, by_variant, pages, provenance, folder)
    if folder is not None:
        _write(result, folder, tornados)
        if docs_folder is not None:
            docs_folder.mkdir(parents=True, exist_ok=True)
            shutil.copytree(folder / "figures", docs_folder / "figures", dirs_exist_ok=True)
            for name in pages:
                shutil.copy(folder / name, docs_folder / name)
    return result


def _write(result: ReproductionResult, folder: Path, tornados: list[Path]) -> None:
    """The pages, figures, cases.csv and reproduction.json into ``folder`` (all or nothing)."""
    reproduction, results = result.reproduction, result.results
    with staged_directory(folder) as stage:
        (stage / "figures").mkdir()
        for figure in reproduction.spec.figures:
            draw_figure(reproduction, results, figure, stage / "figures" / f"fig{figure.number}")
        for image in tornados:
            shutil.copy(image, stage / "figures" / image.name)
        for name, text in result.pages.items():
            (stage / name).write_text(text, encoding="utf-8")
        write_rows_csv(stage / "cases.csv", [
            {"case": r.case.label, "frequency_hz": f, **{m: r.curves[m][i] for m in r.curves}}
            for r in results for i, f in enumerate(reproduction.frequencies_hz)])
        write_json(stage / "reproduction.json", {"provenance": result.provenance, "variants": {
            str(label): {"optima": [{"label": r.case.label, **r.optimum.record, "error": r.error} for r in found],
                         "trends": trend_checks(reproduction, found)}
            for label, found in result.by_variant.items()}})
