"""The API reference of the documentation site is built from the docstrings (docs/reference/index.md): every
public name of ``import rpdrill`` and of ``rpdrill.rocklaw`` is on that page, documented in numpydoc style
(a function's parameters, what it returns and raises, an example; a class's parameters or attributes and an
example), and every example that is not marked to skip runs and prints what it shows."""

import doctest
import inspect
import re
import types
from pathlib import Path

import pytest

import rpdrill
import rpdrill.rocklaw

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = (ROOT / "docs" / "reference" / "index.md").read_text(encoding="utf-8")
PUBLIC = {**{f"rpdrill.{name}": getattr(rpdrill, name) for name in rpdrill.__all__},
          **{f"rpdrill.rocklaw.{name}": getattr(rpdrill.rocklaw, name) for name in rpdrill.rocklaw.__all__}}
# functions whose docstring has no Raises section, and why
RAISE_NOTHING = {"rpdrill.extension": "a decorator that marks what it is given",
                 "rpdrill.shipped_files": "it takes no input",
                 "rpdrill.rocklaw.force_and_state": "it calls the law, whose own errors pass through"}


def kind(value: object) -> str:
    if inspect.isclass(value):
        return "class"
    return "function" if callable(value) and not isinstance(value, types.GenericAlias) else "data"


def sections(doc: str) -> set[str]:
    """The numpydoc section headers of a docstring (a title underlined with dashes)."""
    return set(re.findall(r"^(\w[\w ]*)\n-{3,}$", doc, re.MULTILINE))


def documented_parameters(doc: str) -> set[str]:
    """The names the Parameters section describes (``name : type``, ``a, b : type``, ``*args``, ``**run``)."""
    block = re.search(r"^Parameters\n-+\n(.*?)(?:\n\n\w[\w ]*\n-{3,}|\Z)", doc, re.MULTILINE | re.DOTALL)
    names = set()
    for line in (block.group(1) if block else "").splitlines():
        if line and not line.startswith(" "):
            names.update(name.strip().lstrip("*") for name in line.split(" : ")[0].split(","))
    return names


def test_every_public_name_is_on_the_reference_page():
    shown = set(re.findall(r"^   (\w+)$", REFERENCE, re.MULTILINE))  # the autosummary entries
    by_object = {id(value) for name, value in PUBLIC.items() if name.startswith("rpdrill.") and
                 name.count(".") == 1 and name.split(".")[-1] in shown}
    missing = [name for name, value in PUBLIC.items()
               if name.split(".")[-1] not in shown and not (id(value) in by_object and f"`{name}`" in REFERENCE)]
    assert not missing, missing


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_every_public_name_is_documented_in_numpydoc_style(name):
    value = PUBLIC[name]
    if kind(value) == "data":  # a constant's documentation is the `#:` comment above its assignment
        short = name.rsplit(".", 1)[1]
        sources = [path.read_text(encoding="utf-8") for path in (ROOT / "rocklaw").glob("*.py")]
        assert any(re.search(rf"^#: .+\n(#: .*\n)*{short}\b", source, re.MULTILINE) for source in sources), name
        return
    doc = inspect.getdoc(value) or ""
    found = sections(doc)
    assert "Examples" in found and ">>> " in doc, f"{name}: no example"
    if kind(value) == "class":
        assert found & {"Parameters", "Attributes"}, f"{name}: neither Parameters nor Attributes"
        return
    wanted = {"Returns"} | ({"Raises"} if name not in RAISE_NOTHING else set())
    parameters = set(inspect.signature(value).parameters)
    if parameters:
        wanted.add("Parameters")
        missing = parameters - documented_parameters(doc)
        assert not missing, f"{name}: parameters not documented: {sorted(missing)}"
    assert wanted <= found, f"{name}: missing {sorted(wanted - found)}"


def examples(name: str) -> list[doctest.DocTest]:
    """The examples of a public name, and of the methods and properties its class defines."""
    value, finder = PUBLIC[name], doctest.DocTestFinder(recurse=False)
    found = finder.find(value, name, globs={})
    if kind(value) == "class":
        for member, attribute in vars(value).items():
            target = attribute.fget if isinstance(attribute, property) else attribute
            if not member.startswith("_") and inspect.isfunction(target) and target.__doc__:
                found += finder.find(target, f"{name}.{member}", globs={})
    return [test for test in found if test.examples]


RUNNABLE = sorted(name for name in PUBLIC if kind(PUBLIC[name]) != "data" and any(
    not example.options.get(doctest.SKIP) for test in examples(name) for example in test.examples))


@pytest.mark.parametrize("name", RUNNABLE)
def test_the_examples_run_as_shown(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # the examples write files into the current folder
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    report = []
    for test in examples(name):
        runner.run(test, out=report.append)
    assert runner.failures == 0, "".join(report)
