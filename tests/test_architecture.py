"""The package's structure: installed names, the direction of dependency, no import cycles, and a
run that derives each thing from its scene once."""

from __future__ import annotations

import ast
import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest
from scenes import simulate

import rpdrill.models
import rpdrill.rocklaw
import rpdrill.studies
from rpdrill.models.metrics import summary_metrics
from rpdrill.studies.loading import load_scene

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = {"rpdrill.rocklaw": rpdrill.rocklaw, "rpdrill.models": rpdrill.models, "rpdrill.studies": rpdrill.studies}
LAYER = {"rpdrill.rocklaw": 0, "rpdrill.models": 1, "rpdrill.studies": 2}  # studies -> models -> rocklaw


def _module_imports(path: Path) -> set[str]:
    """rpdrill modules a module imports, at module level or inside functions (a deferred import is a
    dependency too); imports only for type checkers (``if TYPE_CHECKING:``) are not."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    typing_only = {id(node) for block in ast.walk(tree)
                   if isinstance(block, ast.If) and "TYPE_CHECKING" in ast.unparse(block.test)
                   for statement in block.body for node in ast.walk(statement)}
    found: set[str] = set()
    for node in ast.walk(tree):
        if id(node) in typing_only:
            continue
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
    return {name for name in found if name.split(".")[0] == "rpdrill"}


def import_graph() -> dict[str, set[str]]:
    """Installed rpdrill modules -> the rpdrill modules they import (names resolved to modules)."""
    files = {}
    for package, imported in PACKAGES.items():
        for path in Path(imported.__path__[0]).glob("*.py"):
            files[package if path.stem == "__init__" else f"{package}.{path.stem}"] = path
    return {module: {name for name in _module_imports(path) if name in files}
            for module, path in files.items()}


def test_installed_under_one_name_and_nothing_generic(tmp_path):
    for package, imported in PACKAGES.items():
        assert Path(imported.__path__[0]).resolve() == ROOT / package.split(".")[1]
    for generic in ("models", "rocklaw", "studies"):  # from elsewhere than the checkout: not importable
        assert importlib.util.find_spec(f"rpdrill.{generic}") is not None
        done = subprocess.run([sys.executable, "-c", f"import {generic}"], check=False, cwd=tmp_path,
                              capture_output=True)
        assert done.returncode != 0, f"a generic top-level package '{generic}' is installed"


def test_no_module_imports_a_top_level_folder_by_its_bare_name():
    for imported in PACKAGES.values():
        for path in Path(imported.__path__[0]).glob("*.py"):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            names = [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names]
            names += [node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module]
            bare = [name for name in names if name.split(".")[0] in ("models", "rocklaw", "studies")]
            assert not bare, f"{path}: {bare}"


def test_dependencies_run_one_way():
    for module, imports in import_graph().items():
        layer = LAYER[".".join(module.split(".")[:2])]
        upward = [name for name in imports if LAYER[".".join(name.split(".")[:2])] > layer]
        assert not upward, f"{module} imports {upward} (studies -> models -> rocklaw)"


def test_no_import_cycles():
    graph = import_graph()
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


@pytest.fixture
def counts(monkeypatch):
    """Counters of the chain builds, the eigenvalue solves and the static preload solves of a run,
    wherever a module holds a reference to them."""
    import numpy as np

    from rpdrill.models import chain, stability

    counted = {"axial_chain": 0, "static_preload_m": 0, "eigvals": 0}

    def counting(name, function):
        def wrapper(*args, **kwargs):
            counted[name] += 1
            return function(*args, **kwargs)
        return wrapper

    for name in ("axial_chain", "static_preload_m"):
        original = getattr(chain, name)
        wrapped = counting(name, original)
        for module in [m for key, m in sys.modules.items() if key.startswith("rpdrill.")]:
            if getattr(module, name, None) is original:
                monkeypatch.setattr(module, name, wrapped)
    monkeypatch.setattr(stability.np.linalg, "eigvals", counting("eigvals", np.linalg.eigvals))
    return counted


@pytest.mark.parametrize("formulation", ["exudyn", "exact"])
def test_one_run_builds_the_chain_once(counts, formulation):
    """paper_base (preloaded start, standard preset): one chain, one preload solve, at most one
    eigenvalue solve (the Exudyn preset's step), through the run, its metrics and energy account."""
    scene = load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml")
    scene = scene.model_copy(update={"metrics": scene.metrics.model_copy(update={"transient_blows": 2,
                                                                                 "block_blows": 2})})
    result = simulate(scene, formulation, end_time_s=0.1)
    assert summary_metrics(result)["energy_balance_relative_error"] < 1e-2
    assert counts["axial_chain"] == 1 and counts["static_preload_m"] == 1
    assert counts["eigvals"] == (1 if formulation == "exudyn" else 0)
