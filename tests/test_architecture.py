"""The package's structure: installed names, the direction of dependency, no import cycles, and a
run that derives each thing from its scene once."""

from __future__ import annotations

import ast
import functools
import importlib.util
import inspect
import subprocess
import sys
from pathlib import Path

import pytest

import rpdrill

# the counters of the one-run test wrap the chain's builds and the stability check's eigenvalue solves
UNITS = ("rpdrill.models.drill.chain", "rpdrill.models.evaluation.stability")

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("architecture_page", ROOT / "docs" / "architecture_page.py")
architecture = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(architecture)
LAYER = {"rocklaw": 0, "models": 1, "studies": 2, "": 3}  # studies -> models -> rocklaw; the API on top
MAX_MODULES_PER_FOLDER = 15
MAX_LINES_PER_MODULE = 500


def import_graph() -> dict[str, set[str]]:
    """The package's modules -> the package's modules they import, read statically from the files."""
    return architecture.import_graph(ROOT)


def _layer(module: str) -> int:
    return LAYER[module.split(".")[0]]


def test_installed_under_one_name_and_nothing_generic(tmp_path):
    for folder in ("models", "rocklaw", "studies"):
        spec = importlib.util.find_spec(f"rpdrill.{folder}")
        assert spec is not None and Path(spec.submodule_search_locations[0]).resolve() == ROOT / folder
        done = subprocess.run([sys.executable, "-c", f"import {folder}"], check=False, cwd=tmp_path,
                              capture_output=True)
        assert done.returncode != 0, f"a generic top-level package '{folder}' is installed"


def test_the_tests_run_in_a_checkout_of_any_folder_name(tmp_path):
    """A checkout unpacked as ``rpdrill-main`` (not a Python name): pytest must not import the package's
    ``__init__.py`` as a package of tests (conftest.py)."""
    checkout = tmp_path / "rpdrill-main"
    (checkout / "tests").mkdir(parents=True)
    for name in ("pyproject.toml", "__init__.py", "conftest.py"):
        (checkout / name).write_bytes((ROOT / name).read_bytes())
    (checkout / "tests" / "test_front_door.py").write_text("import rpdrill\n\n\ndef test_it():\n"
                                                          "    assert rpdrill.simulate\n")
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider"],
                          cwd=checkout, capture_output=True, text=True, check=False, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:]


def test_the_package_imports_itself_only_relatively():
    """Inside the package every import of its own modules is relative, so that the import graph read
    from the files of a checkout (an editor, an import-graph tool: no install) is the real one."""
    for name, path in architecture.package_files(ROOT).items():
        absolute = [target for target, is_absolute in architecture.module_imports(name, path)
                    if is_absolute and target.split(".")[0] in ("rpdrill", "models", "rocklaw", "studies")]
        assert not absolute, f"{path}: {absolute}"


def test_the_static_graph_holds_the_imports_between_the_folders():
    graph = import_graph()
    between = {(_layer(a), _layer(b)) for a, targets in graph.items() for b in targets}
    assert {(3, 2), (2, 1), (1, 0)} <= between


def test_dependencies_run_one_way():
    for module, imports in import_graph().items():
        upward = [name for name in imports if _layer(name) > _layer(module)]
        assert not upward, f"{module} imports {upward} (studies -> models -> rocklaw)"


def test_no_import_cycles():
    graph = import_graph()
    assert len(graph) > 60  # every module, subpackages included
    state: dict[str, str] = {}
    cycles: list[list[str]] = []

    def walk(module: str, path: list[str]) -> None:
        state[module] = "open"
        for name in sorted(graph[module]):
            if state.get(name) == "open":
                cycles.append(path[path.index(name):] + [name])
            elif name not in state:
                walk(name, path + [name])
        state[module] = "done"

    for module in sorted(graph):
        if module not in state:
            walk(module, [module])
    assert not cycles, cycles


def test_the_architecture_page_matches_the_tree():
    """docs/architecture.md is what docs/architecture_page.py makes of the files today."""
    assert (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8") == architecture.page(ROOT), \
        "docs/architecture.md is out of date: run python docs/architecture_page.py"


def test_folders_and_modules_stay_small_and_names_unique():
    files = architecture.package_files(ROOT)
    folders: dict[Path, int] = {}
    for path in files.values():
        folders[path.parent] = folders.get(path.parent, 0) + 1
        lines = len(path.read_text(encoding="utf-8").splitlines())
        assert lines <= MAX_LINES_PER_MODULE, f"{path}: {lines} lines"
    crowded = {str(folder): count for folder, count in folders.items()
               if folder != ROOT and count > MAX_MODULES_PER_FOLDER}
    assert not crowded
    names: dict[str, list[str]] = {}
    classes: dict[str, list[str]] = {}
    for module, path in files.items():
        if module.startswith("studies"):
            if path.name not in ("__init__.py", "__main__.py"):
                names.setdefault(path.stem, []).append(module)
            for node in ast.parse(path.read_text(encoding="utf-8")).body:
                if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                    classes.setdefault(node.name, []).append(module)
    assert not {name: where for name, where in names.items() if len(where) > 1}
    assert not {name: where for name, where in classes.items() if len(where) > 1}


@pytest.fixture
def counts(monkeypatch):
    """Counters of the chain builds, the eigenvalue solves and the static preload solves of a run,
    wherever a module holds a reference to them."""
    import numpy as np

    from rpdrill.models.drill import chain
    from rpdrill.models.evaluation import stability

    counted = {"axial_chain": 0, "static_preload_m": 0, "eigvals": 0}

    def counting(name, function):
        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            counted[name] += 1
            return function(*args, **kwargs)
        return wrapper

    for name in ("axial_chain", "static_preload_m"):
        original = inspect.unwrap(getattr(chain, name))
        wrapped = counting(name, original)
        for module in [m for key, m in sys.modules.items() if key.startswith("rpdrill.")]:
            # a module first imported while an earlier test counted holds that test's counter: counted here too
            if callable(held := getattr(module, name, None)) and inspect.unwrap(held) is original:
                monkeypatch.setattr(module, name, wrapped)
    monkeypatch.setattr(stability.np.linalg, "eigvals", counting("eigvals", np.linalg.eigvals))
    return counted


@pytest.mark.parametrize("formulation", ["exudyn", "exact"])
def test_one_run_builds_the_chain_once(counts, formulation):
    """paper_base (preloaded start, standard preset): one chain, one preload solve, at most one
    eigenvalue solve (the Exudyn preset's step), through the run, its metrics and energy account."""
    scene = rpdrill.load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml")
    scene = scene.model_copy(update={"metrics": scene.metrics.model_copy(update={"transient_blows": 2,
                                                                                 "block_blows": 2})})
    result = rpdrill.simulate(scene.with_solver(formulation, end_time_s=0.1), budget=None)
    assert result.metrics["energy_balance_relative_error"] < 1e-2 and result.energy.relative_residual() < 1e-2
    assert counts["axial_chain"] == 1 and counts["static_preload_m"] == 1
    assert counts["eigvals"] == (1 if formulation == "exudyn" else 0)
