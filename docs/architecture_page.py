"""docs/architecture.md and its picture, generated from the files of the checkout (nothing installed).

    python docs/architecture_page.py          # writes docs/architecture.md and docs/architecture.svg

The import graph is read statically: every ``.py`` file of the package (the root ``__init__.py``,
``rocklaw/``, ``models/``, ``studies/`` and their subpackages), every ``import`` and ``from ... import``
at any depth (relative imports resolved as Python does; imports only for type checkers left out).
The picture draws it between packages; the page lists each package with its modules, what it holds
and what it imports, and follows one value, the impact frequency, from a study file to the solver
(:data:`FREQUENCY_PATH`: every function it names is looked up in the files, so the page cannot name
one that is gone). tests/test_architecture.py checks that the page matches the tree.
"""

from __future__ import annotations

import ast
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("rocklaw", "models", "studies")

# what each package holds (one paragraph each; a package missing here fails the page's test)
ROLES = {
    "": "The public API: `import rpdrill` re-exports the scene, the simulate and study functions, the result "
        "and the errors a user catches (docs/api.md). Nothing else imports it.",
    "rocklaw": "The rock contact laws (the paper's Jenkins law, a bilinear law): each written once against "
               "evaluation backends (NumPy, floats, Exudyn symbolic) and declared as a piecewise-linear mode "
               "table; the Exudyn user element; Exudyn itself, imported for rpdrill. Knows nothing of scenes.",
    "models": "The drill models (the subpackages below): knows nothing of YAML files, studies or the "
              "command line.",
    "models.definition": "What a scene is: the typed scene (data only), validated edits of it by key path and "
                         "the messages of bad values, the outputs a scene can ask for, the connector types, "
                         "the registry of formulations and their solver keys, the code of one's own a scene may "
                         "name and when it runs (registered or allowed: a scene is data).",
    "models.drill": "The drill string's mechanics: the chain of bodies and connectors (incidence, stiffness, "
                    "static preload), its modes, its piecewise-linear modes of contact, the impact pulse, bit "
                    "indexing, the piston, a rod as a wave element (impedance, transit time, its ends' law).",
    "models.evaluation": "What a run gives: the result and its time series, its typed records (solver, steady "
                         "state, items of one's own), the energy account, metrics, "
                         "stability checks and step bounds, the solver presets, comparisons between runs, "
                         "work-precision fronts, stress-wave checks.",
    "models.waves": "Rods carried as waves: the characteristics at a stated step (the waves in flight, "
                    "stored per rod end), the linear system of bodies, massless faces and arriving waves between "
                    "two grid times integrated exactly (its compiled fast path, its works), the static preload "
                    "and step of such a drill, and the exact and Exudyn formulations of a scene with wave rods.",
    "models.steady": "The drill's steady state found, not waited for: the periodic orbit relative to the borehole "
                     "bottom by shooting (the exact map's Jacobian from matrix exponentials and saltation "
                     "matrices, finite differences for the other formulations), its Floquet multipliers, the "
                     "regime of a scene (period-1, period-n, none), continuation along a scan and its "
                     "bifurcations.",
    "models.runs": "The one path from a prepared scene to its `rpdrill.Result`: the time run, or the steady state "
                   "the scene's solver.steady_state asks for, with its typed records.",
    "models.solvers": "Preparing a scene for a run and the three formulations of one model: the Exudyn "
                      "multibody system, the exact piecewise-linear propagation (its linear system and "
                      "compiled kernels), the paper's Eq. 4 as a SciPy ODE; a run's cost estimate.",
    "studies": "Everything around a model: reading YAML, scans and analyses, reports and the command line "
               "(the subpackages below, and two modules of their own).",
    "studies.api": "The library's functions that the root package re-exports (load a scene, simulate it into "
                   "a Result, load and run a study into a pandas table); the command line is their client, "
                   "as it is of each analysis's own library call (`calibrate`, `sensitivity`, `accuracy`, "
                   "`reproduce`, `rotation_report`, `advise`, `crosscheck`).",
    "studies.study_runs": "Running studies into their folders: the points of several studies as one run on "
                          "one pool, each study's results table, optima and plots.",
    "studies.inputs": "Reading YAML strictly (duplicate keys, YAML 1.2 numbers, sizes) into the models' "
                      "validated types; the spec base the study, calibration and other files share.",
    "studies.display": "How quantities are shown: the catalogue of every metric's and parameter's name, symbol "
                       "and display unit, and text/Markdown tables.",
    "studies.runtime": "Running many points: one point (a typed scene made by `Scene.with_`, prepared, run "
                       "into a row), process pools and Dask, resumable results tables (pandas DataFrames in "
                       "memory, CSV on disk, one reader), interrupts, progress, output folders, budgets "
                       "checked before anything runs.",
    "studies.scan": "Scans: studies (a base scene's points over axes, run into their folders), the curves "
                    "along one axis the analyses run (one worker a curve), and the one record of a curve's "
                    "optimum (best point, main lobe, bands, why there is none) every analysis uses.",
    "studies.calibration": "Fitting scene parameters within argued bounds so that scans put their optima where "
                           "the paper does (differential evolution, checkpointed), and its report.",
    "studies.sensitivity": "The paper's section 3.3: one-at-a-time and SALib global sensitivity of the optima.",
    "studies.accuracy": "Work-precision studies: every solver setting's error against its CPU time.",
    "studies.advice": "The operating point that maximises a metric within bounds (`rpdrill advise`) and "
                      "its report.",
    "studies.hole": "A hole over its depth (`rpdrill hole`): the hole file, its scene rod by rod and layer by "
                    "layer, one steady run per rod count and layer, the rows against depth, their figure.",
    "studies.crosscheck": "The Exudyn model against the paper's Eq. 4 as an ODE over the first blows.",
    "studies.reproduction": "The paper reproduced: each headline case scanned, its optima against the "
                            "paper's, the trends checked.",
    "studies.figures": "Every figure (matplotlib): scans, maps, time series, work-precision, tornado, the "
                       "paper's figures redrawn, and the plot tasks a pool's workers draw.",
    "studies.drawings": "Pictures of the drill itself: the string drawn to scale, its animation over the last "
                        "blows, a built Exudyn system drawn from its own graphics, Exudyn's solution file.",
    "studies.pages": "The generated documentation pages (reproduction, parameters, sensitivity, figures, "
                     "rotation).",
    "studies.cli": "The `rpdrill` command line: `main.py` (argparse, exit statuses, one-line warnings) and a "
                   "module per command; a command parses, calls the library and prints.",
}


# The impact frequency from a study file to the solver and back into the table: (module, name defined
# there, what the value is at that step). A step whose name the module no longer defines fails the page.
FREQUENCY_PATH = (
    ("studies.inputs.reading", "read_yaml",
     ("the study file read strictly: `scan: {impact.frequency_hz: {from: 10, to: 120, step: 5}}`, YAML 1.2 "
     "numbers (a mapping of floats)")),
    ("studies.scan.study", "load_study",
     ("validated as the study's `scan: dict[str, Axis]` (pydantic), the key path checked against the scene's "
     "fields (`studies.inputs.specs.check_scene_path`), `Axis.expand` giving the values as floats")),
    ("studies.scan.study", "_combine",
     "each point's axis values, `{\"impact.frequency_hz\": 65.0}`, crossed or zipped with the other axes"),
    ("studies.runtime.point_runs", "point_scene",
     ("the point's typed scene: `base.with_(values)` (`Scene.with_`, validated as a scene file is), "
     "`scene.impact.frequency_hz` a positive float whose period is longer than the pulse; a bad value names "
     "its axis")),
    ("models.definition.scene", "Scene.with_", "the validated copy (models.definition.validation.with_changes)"),
    ("studies.runtime.point_runs", "prepare_point",
     ("prepared once (`models.solvers.simulation.prepare`): the `Simulation` holds the scene's `impact` and a "
     "solver step fitted to its period `impact.period_s`; the prepared object goes to a worker as it is")),
    ("studies.runtime.point_runs", "run_point",
     ("in the worker: `models.runs.scene_run.run`, the time run (`models.solvers.time_run.time_run`) or the "
     "periodic orbit the scene asks for, the formulation (exact, Exudyn, ODE) placing the blows every "
     "`impact.period_s` (`models.drill.pulse`); the row it returns holds floats")),
    ("studies.runtime.resumable", "run_tables",
     ("the row appended to `results.csv` (`studies.runtime.tables.append_rows`: text only in the file) and "
     "the table read back typed (`studies.runtime.tables.read_table`, the one place a number is read from text)")),
    ("studies.scan.study_optima", "study_optima",
     ("the optimum along the frequency from the typed column (`studies.scan.curve_optima.curve_optimum`); "
     "the analyses' curves take the same steps from `studies.scan.curves.run_curve`")),
)


# One scene from `rpdrill.simulate` to its `rpdrill.Result`: the one run path (same form as FREQUENCY_PATH).
SCENE_ROUTE = (
    ("studies.api", "simulate", "the call's arguments checked; the scene given, or read from its file"),
    ("studies.inputs.reading", "scene_and_source",
     "a file, or a shipped scene by its name (`studies.inputs.shipped.shipped_path`), read strictly into a `Scene`"),
    ("studies.inputs.reading", "prepare_scene",
     ("prepared once (`models.solvers.simulation.prepare`): the chain, the rock law, the solver settings, the start; "
     "a scene that cannot run as given refused naming its key")),
    ("studies.runtime.budgets", "Budget.check_run", "its steps and memory estimated and held against the budget"),
    ("models.runs.scene_run", "run",
     ("the one path from a prepared scene to its result: the time run, or the steady state "
     "`solver.steady_state: periodic` asks for (`models.steady.regimes.RegimeFinder`, its runs by the same "
     "formulation)")),
    ("models.solvers.time_run", "time_run",
     ("the formulation's run (`models.solvers.simulation.implementation`: exact, Exudyn or ODE), its samples and "
     "a `SolverRecord` of what it did")),
    ("models.evaluation.run_result", "Result",
     ("the typed result: metrics (`models.evaluation.metrics.summary_metrics`, on first use), the time series as a "
     "DataFrame, the `SteadyStateRecord`, the source and the code it ran")),
)


def defines(path: Path, name: str) -> bool:
    """Whether a module's file defines ``name`` at its top level (``Class.method`` inside the class)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    outer, _, inner = name.partition(".")
    found = next((node for node in tree.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))
                  and node.name == outer), None)
    if found is None or not inner:
        return found is not None
    return any(isinstance(node, ast.FunctionDef) and node.name == inner for node in getattr(found, "body", []))


def route_section(title: str, intro: str, route: tuple[tuple[str, str, str], ...], root: Path = ROOT) -> list[str]:
    """A section following ``route`` (module, name defined there, what happens): a flowchart and its steps;
    SystemExit naming a step the files no longer define."""
    files = package_files(root)
    gone = [f"{module}.{name}" for module, name, _ in route if module not in files or not defines(files[module], name)]
    if gone:
        raise SystemExit(f"docs/architecture_page.py: the route '{title}' names {', '.join(gone)}, which the files "
                         "do not define")
    lines = [f"## {title}", "", intro, "", "```mermaid", "flowchart TD"]
    lines += [f'    step{i}["{i}. {module}.{name}"]' + (f" --> step{i + 1}" if i < len(route) else "")
              for i, (module, name, _) in enumerate(route, 1)]
    lines += ["```", ""]
    lines += [f"{i}. `{module}.{name}`: {text}." for i, (module, name, text) in enumerate(route, 1)]
    return [*lines, ""]


def frequency_path(root: Path = ROOT) -> list[str]:
    """The page's sections on :data:`SCENE_ROUTE` and :data:`FREQUENCY_PATH`."""
    scene = route_section(
        "One scene from `rpdrill.simulate` to its result",
        ("The route of one run (`rpdrill simulate` is the same call, then `save_result`): one way from a prepared "
         "scene to a result whatever its `solver.steady_state`; the study's points take it from step 5 in their "
         "workers (`studies.runtime.point_runs.run_prepared`)."), SCENE_ROUTE, root)
    frequency = route_section(
        "The impact frequency from a study file to the solver",
        ("One value followed through the layers (`studies/paper/frequency_scan.yaml`): it is a typed "
         "value at every step, never written into a raw mapping and never read back from text but by the "
         "table's one reader."), FREQUENCY_PATH, root)
    return [*scene, *frequency]


def package_files(root: Path = ROOT) -> dict[str, Path]:
    """Every module of the package, from the files: dotted name below ``rpdrill`` ("" the package
    itself, "models.definition.scene", "studies.cli.main", ...) -> path."""
    files = {"": root / "__init__.py"}
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            files[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return files


def module_imports(name: str, path: Path) -> list[tuple[str, bool]]:
    """(imported module or module.attribute, absolute?) of one module, at any depth, imports only for
    type checkers (``if TYPE_CHECKING:``) too (a type named across a boundary is a dependency as well);
    relative imports resolved against its package."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = [part for part in (name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]) if part]
    found: list[tuple[str, bool]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, True) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                if node.level - 1 > len(package):
                    raise ValueError(f"{path}: a relative import beyond the package")
                base = package[:len(package) - (node.level - 1)]
                module = ".".join(base + ([node.module] if node.module else []))
                found.append((module, False))
                found += [(f"{module}.{alias.name}".strip("."), False) for alias in node.names]
            elif node.module:
                found.append((node.module, True))
    return found


def import_graph(root: Path = ROOT) -> dict[str, set[str]]:
    """The package's modules -> the package's modules they import."""
    files = package_files(root)
    return {name: {target for target, _ in module_imports(name, path) if target in files}
            for name, path in files.items()}


def package_of(module: str, files: dict[str, Path]) -> str:
    """The node a module belongs to in the picture: itself for a package's ``__init__`` and for a module
    directly in ``studies/`` (``studies.api``), its package otherwise."""
    if files[module].name == "__init__.py" or module.rpartition(".")[0] == "studies":
        return module
    return module.rpartition(".")[0]


def package_graph(root: Path = ROOT) -> dict[str, set[str]]:
    """Packages -> the other packages their modules import."""
    files = package_files(root)
    edges: dict[str, set[str]] = defaultdict(set)
    for module, targets in import_graph(root).items():
        source = package_of(module, files)
        edges[source] |= {package_of(t, files) for t in targets} - {source}
        edges.setdefault(source, set())
    imported = set().union(*edges.values())
    return {node: targets for node, targets in edges.items() if targets or node in imported}  # no empty __init__


def layers(graph: dict[str, set[str]]) -> dict[str, int]:
    """Each package's layer: 0 for one that imports no other package, else one above the highest it
    imports (the graph has no cycle: tests/test_architecture.py)."""
    level: dict[str, int] = {}

    def of(package: str) -> int:
        if package not in level:
            level[package] = 1 + max((of(t) for t in graph[package]), default=-1)
        return level[package]

    for package in graph:
        of(package)
    return level


def label(package: str) -> str:
    return package or "rpdrill (api)"


def draw(graph: dict[str, set[str]], path: Path) -> None:
    """The package graph drawn bottom-up by layer (an arrow from importer to imported)."""
    import matplotlib
    from matplotlib.figure import Figure

    level = layers(graph)
    rows: dict[int, list[str]] = defaultdict(list)
    for package in sorted(graph, key=lambda p: (p.split(".")[0], p)):
        rows[level[package]].append(package)
    position = {}
    for y, packages in rows.items():
        for i, package in enumerate(packages):
            position[package] = ((i + 1) / (len(packages) + 1), y)
    colours = {"rocklaw": "#cfe2f3", "models": "#d9ead3", "studies": "#fff2cc", "": "#f4cccc"}
    fig = Figure(figsize=(13, 1.3 * (max(rows) + 1)))
    ax = fig.subplots()
    for source, targets in sorted(graph.items()):
        for target in sorted(targets):
            (x0, y0), (x1, y1) = position[source], position[target]
            ax.annotate("", xy=(x1, y1 + 0.18), xytext=(x0, y0 - 0.18),
                        arrowprops={"arrowstyle": "->", "color": "#888888", "lw": 0.7, "shrinkA": 2, "shrinkB": 2})
    for package, (x, y) in position.items():
        ax.text(x, y, label(package).removeprefix("studies."), ha="center", va="center", fontsize=9,
                bbox={"boxstyle": "round,pad=0.35", "fc": colours[package.split(".")[0]], "ec": "#555555"})
    ax.set_xlim(0, 1)
    ax.set_ylim(-0.6, max(rows) + 0.6)
    ax.axis("off")
    ax.set_title("rpdrill: packages and their imports (arrow: imports; blue rocklaw, green models, "
                 "yellow studies' subpackages, red the API), read from the files", fontsize=10)
    fig.tight_layout()
    with matplotlib.rc_context({"svg.hashsalt": "rpdrill"}):  # the same file for the same tree
        fig.savefig(path, metadata={"Date": None})


def page(root: Path = ROOT) -> str:
    """docs/architecture.md."""
    files = package_files(root)
    graph = package_graph(root)
    level = layers(graph)
    modules: dict[str, list[str]] = defaultdict(list)
    for module in files:
        if files[module].name != "__init__.py":
            modules[package_of(module, files)].append(module.rpartition(".")[2])
    missing = sorted(set(graph) - set(ROLES))
    if missing:
        raise SystemExit(f"docs/architecture_page.py: no paragraph for the package(s) {', '.join(missing)}")
    lines = ["# Architecture", "",
             ("Generated from the files of the checkout by `python docs/architecture_page.py` (the import graph "
              "read statically: every import of every module, relative imports resolved; nothing installed). "
              "tests/test_architecture.py checks that this page matches the tree, that dependencies run one "
              "way (studies -> models -> rocklaw, the API on top) and that no import forms a cycle."), "",
             ("The checkout is the package `rpdrill`: its `__init__.py` is the public API, its folders "
              "`rocklaw/`, `models/` and `studies/` are the subpackages `rpdrill.rocklaw`, `rpdrill.models`, "
              "`rpdrill.studies` (pyproject.toml maps them; every import inside the package is relative, so "
              "an editor or an import-graph tool follows them without an install)."), "",
             "![packages and their imports](architecture.svg)", "",
             "Layer 0 imports no other package; each package imports only packages of lower layers.", ""]
    for package in sorted(graph, key=lambda p: (-level[p], p)):
        imports = ", ".join(f"`{label(t)}`" for t in sorted(graph[package])) or "none"
        held = ", ".join(f"`{m}`" for m in sorted(modules[package])) or "(only `__init__.py`)"
        lines += [f"## `{label(package)}` (layer {level[package]})", "", ROLES[package], "",
                  f"Modules: {held}.", "", f"Imports: {imports}.", ""]
    return "\n".join(lines + frequency_path(root))


def main() -> None:
    (ROOT / "docs" / "architecture.md").write_text(page(), encoding="utf-8")
    draw(package_graph(), ROOT / "docs" / "architecture.svg")
    print("wrote docs/architecture.md, docs/architecture.svg", file=sys.stderr)


if __name__ == "__main__":
    main()
