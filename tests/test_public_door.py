"""Tests go where a user goes (docs/development.md, "Tests through the public door").

A test module reaches rpdrill through its public door: ``import rpdrill``, ``import rpdrill.rocklaw`` and the
public names of both (their ``__all__``). A unit test of internal modules names them in a module-level
``UNITS`` tuple (a module or a package, dotted from ``rpdrill``) and reaches nothing internal beyond them, by
import or by a patched path (``monkeypatch.setattr("rpdrill....", ...)``); every unit it names it uses.
"""

import ast
import importlib.util
from dataclasses import dataclass
from pathlib import Path

import pytest

import rpdrill
import rpdrill.rocklaw

TESTS = Path(__file__).resolve().parent
MODULES = sorted([*TESTS.glob("*.py"), TESTS.parent / "conftest.py"])
PUBLIC = {"rpdrill": set(rpdrill.__all__), "rpdrill.rocklaw": set(rpdrill.rocklaw.__all__)}
PATCHERS = {"setattr", "delattr", "patch", "import_module"}


@dataclass(frozen=True)
class Reach:
    """An internal module a test reaches, and the line where."""

    module: str
    line: int


def internal_reaches(tree: ast.Module) -> list[Reach]:
    """Every internal module, or name in one, a test module imports or patches by its dotted path."""
    reaches = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            reaches += [Reach(alias.name, node.lineno) for alias in node.names
                        if alias.name.startswith("rpdrill.") and alias.name not in PUBLIC]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").startswith("rpdrill"):
            if node.module in PUBLIC:
                reaches += [Reach(f"{node.module}.{alias.name}", node.lineno) for alias in node.names
                            if alias.name not in PUBLIC[node.module]]
            else:
                reaches += [Reach(f"{node.module}.{alias.name}", node.lineno) for alias in node.names]
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", "")) in PATCHERS:
            reaches += [Reach(arg.value, node.lineno) for arg in node.args[:1] if isinstance(arg, ast.Constant) and isinstance(arg.value, str)
                        and arg.value.startswith("rpdrill.")]
    return reaches


def declared_units(tree: ast.Module) -> tuple[str, ...] | None:
    """The module's ``UNITS`` tuple, or None."""
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "UNITS" for t in node.targets):
            return tuple(ast.literal_eval(node.value))
    return None


def unit_tests(tree: ast.Module) -> list[str]:
    """The test functions of a module that reach an internal module: by an import or patch of their own, by a name
    the module imported from one, or through the module's functions and fixtures they call or take."""
    internal = {alias.asname or alias.name for node in tree.body if isinstance(node, (ast.Import, ast.ImportFrom))
                for alias in node.names if internal_reaches(ast.Module(body=[node], type_ignores=[]))
                and (alias.asname or isinstance(node, ast.ImportFrom))}  # ``import rpdrill.a.b`` binds ``rpdrill``
    functions = {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}

    def reaches(function: ast.FunctionDef, seen: frozenset[str]) -> bool:
        if internal_reaches(ast.Module(body=[function], type_ignores=[])):
            return True
        used = {node.id for node in ast.walk(function) if isinstance(node, ast.Name)} | \
            {arg.arg for arg in function.args.args}
        dotted = [ast.unparse(node).split(".") for node in ast.walk(function) if isinstance(node, ast.Attribute)]
        if any(parts[0] == "rpdrill" and len(parts) > 2 and (parts[1] in ("models", "studies") or parts[1] == "rocklaw"
               and parts[2] not in PUBLIC["rpdrill.rocklaw"]) for parts in dotted):  # rpdrill.models.x.y after ``import rpdrill.models.x``
            return True
        return bool(used & internal) or any(reaches(functions[name], seen | {name})
                                             for name in used & set(functions) - seen)

    return [name for name, function in functions.items()
            if name.startswith("test_") and reaches(function, frozenset({name}))]


def within(module: str, unit: str) -> bool:
    return module == unit or module.startswith(unit + ".")


@pytest.mark.parametrize("path", MODULES, ids=lambda p: p.name)
def test_a_test_module_reaches_nothing_internal_beyond_the_units_it_names(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    reaches, units = internal_reaches(tree), declared_units(tree) or ()
    beyond = [f"line {r.line}: {r.module}" for r in reaches if not any(within(r.module, u) for u in units)]
    assert not beyond, f"{path.name} reaches internal modules it does not name in UNITS: {beyond}"
    for unit in units:
        assert importlib.util.find_spec(unit) is not None, f"{path.name}: UNITS names {unit}, not a module"
        assert any(within(r.module, unit) for r in reaches), f"{path.name}: UNITS names {unit}, which it never uses"


def test_the_check_sees_imports_patches_and_private_names() -> None:
    source = ("import rpdrill\nfrom rpdrill import simulate, models\nimport rpdrill.models.drill.chain\n"
              "from rpdrill.rocklaw.modes import check_mode_forces\nfrom rpdrill.rocklaw import JenkinsRock\n"
              "def test(monkeypatch):\n    monkeypatch.setattr('rpdrill.studies.hole.hole_run.run', None)\n")
    assert [(r.module, r.line) for r in internal_reaches(ast.parse(source))] == [
        ("rpdrill.models", 2), ("rpdrill.models.drill.chain", 3), ("rpdrill.rocklaw.modes.check_mode_forces", 4),
        ("rpdrill.studies.hole.hole_run.run", 7)]



def test_a_test_counts_as_a_unit_test_when_it_or_its_helpers_reach_inside() -> None:
    source = ("import rpdrill\nimport rpdrill.models.drill.chain\nfrom rpdrill.models.solvers.simulation import prepare\n"
              "def helper(s):\n    return prepare(s)\n"
              "def drill():\n    return helper(1)\n"
              "def test_public():\n    assert rpdrill.simulate(rpdrill.load_scene('paper_base')).metrics\n"
              "def test_direct():\n    prepare(1)\n"
              "def test_by_a_helper():\n    drill()\n"
              "def test_by_a_fixture(drill):\n    pass\n"
              "def test_dotted():\n    rpdrill.models.drill.chain.axial_chain(1)\n")
    assert unit_tests(ast.parse(source)) == ["test_direct", "test_by_a_helper", "test_by_a_fixture", "test_dotted"]

if __name__ == "__main__":  # the counts docs/development.md states
    tests = [(path, ast.parse(path.read_text(encoding="utf-8"))) for path in MODULES if path.name.startswith("test_")]
    count = sum(1 for _, tree in tests for node in tree.body
                if isinstance(node, ast.FunctionDef) and node.name.startswith("test_"))
    units = sum(len(unit_tests(tree)) for _, tree in tests)
    print(f"{count} test functions: {count - units} reach only the public door, {units} are unit tests of the "
          f"modules their file names; {sum(1 for _, tree in tests if not internal_reaches(tree))} of {len(tests)} "
          "test modules reach no internal module")
