"""``rpdrill reproduce --out DIR``: the paper reproduced on the shipped scene, and the generated docs.

Scans every case of the reproduction file (default ``studies/paper/reproduction.yaml``) on a 1 Hz
grid with the exact formulation and writes into DIR: ``reproduction.md`` (the paper against rpdrill,
the trends, the sub-harmonic lobes), ``figures.md`` with the paper's Figs. 2-6 redrawn
(``figures/fig<N>.png``/``.svg``), ``parameters.md`` (the shipped scene's values, the bounds and reasons of
the reproduction file's ``calibration`` file, the rock-mode resonances, and the calibration run given by
``--calibration``),
``sensitivity.md`` when ``--sensitivity`` names a sensitivity run, ``cases.csv`` (every curve) and
``reproduction.json``. With ``--docs DIR`` the pages and figures are also copied into that folder
(``--docs docs`` in a checkout). Exit 1 when an optimum the paper states is not reached within the
tolerance or a trend does not hold.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import shlex
import shutil
import sys
from pathlib import Path

from ..calibration.calibration_spec import load_calibration
from ..figures.paper_figures import draw_figure
from ..inputs.reading import InputError
from ..pages.paper_pages import figures_page, parameters_page, reproduction_page, sensitivity_page
from ..reproduction.paper_reproduction import Reproduction, load_reproduction, reproduce, trend_checks, within
from ..runtime.budgets import Budget
from ..runtime.output_files import check_out, staged_directory, write_json, write_rows_csv
from ..runtime.pools import pool
from .options import add_runner_arguments

PAPER = Path(__file__).resolve().parents[1] / "paper"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("reproduction", nargs="?", default=str(PAPER / "reproduction.yaml"),
                        help="reproduction YAML file (default: the paper's, studies/paper/reproduction.yaml)")
    parser.add_argument("--out", required=True, help="output directory: new, empty, or an earlier reproduction's")
    parser.add_argument("--overwrite", action="store_true", help="write into --out although it holds other files")
    parser.add_argument("--calibration", type=Path, help="output directory of `rpdrill calibrate` for parameters.md")
    parser.add_argument("--sensitivity", type=Path, help="output directory of `rpdrill sensitivity` for sensitivity.md")
    parser.add_argument("--docs", type=Path, help="also copy the pages and figures into this folder (e.g. docs)")
    add_runner_arguments(parser)


def _shown(path: str | Path) -> str:
    """A path as a page shows it: relative to the working folder where it lies below it."""
    path = Path(path)
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def made_by(args: argparse.Namespace, reproduction: Reproduction) -> str:
    """The command line that made the pages and the input files it read, as the pages state them."""
    words = ["rpdrill", "reproduce"]
    if Path(args.reproduction).resolve() != (PAPER / "reproduction.yaml").resolve():
        words.append(_shown(args.reproduction))
    words += ["--out", _shown(args.out)]
    for option in ("calibration", "sensitivity", "docs"):
        if getattr(args, option) is not None:
            words += [f"--{option}", _shown(getattr(args, option))]
    inputs = [_shown(args.reproduction)]
    if isinstance(reproduction.spec.base_scene, str):
        inputs.append(_shown(Path(args.reproduction).parent / reproduction.spec.base_scene))
    if reproduction.calibration_file is not None:
        inputs.append(_shown(reproduction.calibration_file))
    if args.calibration is not None:
        inputs.append(_shown(args.calibration / "calibration.json"))
    if args.sensitivity is not None:
        inputs.append(_shown(args.sensitivity / "summary.json"))
    return f"`{shlex.join(words)}` (inputs: {', '.join(f'`{name}`' for name in inputs)})"


def run(args: argparse.Namespace) -> int:
    check_out(args.out, args.overwrite, "reproduction.json")
    if args.docs is not None:
        check_out(args.docs, True, option="--docs")
    for option, command in (("calibration", "calibrate"), ("sensitivity", "sensitivity")):
        folder = getattr(args, option)
        if folder is not None and not folder.is_dir():
            raise InputError(f"--{option}: {folder}: not a folder; give the --out of `rpdrill {command}`")
    reproduction = load_reproduction(args.reproduction)
    # only the calibration's bounds and reasons are read (its search is not run): no limit on its CPU estimate
    calibration = None if reproduction.calibration_file is None else \
        load_calibration(reproduction.calibration_file, Budget(accept_long=True))
    with pool(args.dask, args.workers) as (label, runner):
        print(f"{reproduction.spec.name}: {len(reproduction.spec.cases)} cases x {len(reproduction.frequencies_hz)} "
              f"frequencies on {label}", file=sys.stderr)
        by_variant, cost = reproduce(reproduction, runner)
    results = by_variant[None]
    provenance = {"cases": len(results), **cost, "rpdrill_version": importlib.metadata.version("rpdrill"),
                  "exudyn_version": importlib.metadata.version("exudyn")}
    stated = made_by(args, reproduction)
    pages = {"reproduction.md": reproduction_page(reproduction, by_variant, provenance, stated),
             "parameters.md": parameters_page(reproduction, results, calibration, args.calibration, stated)}
    with staged_directory(args.out) as stage:
        (stage / "figures").mkdir()
        figures = []
        for figure in reproduction.spec.figures:
            draw_figure(reproduction, results, figure, stage / "figures" / f"fig{figure.number}")
            figures.append((figure.number, figure.title, f"figures/fig{figure.number}.svg"))
        pages["figures.md"] = figures_page(figures, stated)
        if args.sensitivity is not None:
            tornados = sorted(args.sensitivity.glob("tornado_*.svg"))
            for image in tornados:
                shutil.copy(image, stage / "figures" / image.name)
            pages["sensitivity.md"] = sensitivity_page(args.sensitivity, [f"figures/{i.name}" for i in tornados],
                                                       stated)
        for name, text in pages.items():
            (stage / name).write_text(text, encoding="utf-8")
        write_rows_csv(stage / "cases.csv", [
            {"case": r.case.label, "frequency_hz": f, **{m: r.curves[m][i] for m in r.curves}}
            for r in results for i, f in enumerate(reproduction.frequencies_hz)])
        write_json(stage / "reproduction.json", {"provenance": provenance, "variants": {
            str(label): {"optima": [r.optimum for r in found], "trends": trend_checks(reproduction, found)}
            for label, found in by_variant.items()}})
    if args.docs is not None:
        args.docs.mkdir(parents=True, exist_ok=True)
        shutil.copytree(Path(args.out) / "figures", args.docs / "figures", dirs_exist_ok=True)
        for name in pages:
            shutil.copy(Path(args.out) / name, args.docs / name)
    trends = trend_checks(reproduction, results)
    stated = [r for r in results if r.case.paper.optimum_hz is not None]
    reached = [r for r in stated if within(r.optimum["main_hz"], r.case.paper, reproduction.spec.tolerance)]
    print(f"{reproduction.spec.name}: {sum(t['rises'] for t in trends)} of {len(trends)} trends hold; "
          f"{len(reached)} of {len(stated)} optima the paper states reached within "
          f"{reproduction.spec.tolerance:.0%}; wrote {args.out}" + (f" and {args.docs}" if args.docs else ""),
          file=sys.stderr)
    return 0 if len(reached) == len(stated) and all(t["rises"] for t in trends) else 1
