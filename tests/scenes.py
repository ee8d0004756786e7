"""Scenes for tests: the frozen test drill (tests/test_drill.yaml) with overrides by dotted key path, and the
YAML reader the tests read their files with (``read_yaml``: ruamel.yaml's safe loader, YAML 1.2 as rpdrill reads
it; rpdrill's own reader adds refusals of bad input, which the tests' files are not)."""

from __future__ import annotations

import copy
import functools
from pathlib import Path
from typing import Any

from ruamel.yaml import YAML

import rpdrill
from rpdrill import Scene

PAPER_BASE = Path(__file__).resolve().parent / "test_drill.yaml"

# Overrides that make the test drill crush on every blow (used where a test needs crushing).
CRUSHING = {"impact.amplitude_n": 400e3, "impact.frequency_hz": 45.0}
# The paper's Eq. 4 as printed: no carriage, the shock absorber anchored to ground, the feed on every body.
PER_BODY = {"drill_string.bodies.carriage": None, "drill_string.connectors.shock_absorber.from": "ground",
            "feed.acts_on": "every_body"}


def read_yaml(path: str | Path) -> dict[str, Any]:
    """The mapping in a YAML file (a copy of the text's parse, kept: the tests read the shipped scenes often)."""
    return copy.deepcopy(_parsed(Path(path).read_text(encoding="utf-8")))


@functools.lru_cache(maxsize=32)
def _parsed(text: str) -> Any:
    return YAML(typ="safe", pure=True).load(text)


def scene_dict(path: Path = PAPER_BASE, **overrides: Any) -> dict:
    """The scene file as a dict with ``{"a.b.c": value}`` overrides (use ``None`` to delete a key)."""
    data = read_yaml(path)
    for dotted, value in overrides.items():
        *parents, key = dotted.split(".")
        node = data
        for part in parents:
            node = node.setdefault(part, {})
        if value is None:
            node.pop(key, None)
        else:
            node[key] = value
    return data


def scene(**overrides: Any) -> Scene:
    """``scene_dict`` validated; keyword names use ``__`` for dots (``impact__frequency_hz=50``)."""
    return Scene.model_validate(scene_dict(**{k.replace("__", "."): v for k, v in overrides.items()}))


def crushing_scene(**overrides: Any) -> Scene:
    return scene(**({k.replace(".", "__"): v for k, v in CRUSHING.items()} | overrides))


def result_of(scene: Scene, formulation: str | None = None, **options: Any) -> rpdrill.Result:
    """Run ``scene`` with ``formulation`` (default: the scene's) and solver ``options``: ``rpdrill.simulate``,
    unbudgeted (tests run scenes of many steps on purpose); the Result a user holds (metrics, energy account)."""
    return rpdrill.simulate(scene.with_solver(formulation, **options), budget=None)


def simulate(scene: Scene, formulation: str | None = None, **options: Any) -> Any:
    """:func:`result_of`'s formulation's result (``Result.raw``: every sample, the chain)."""
    return result_of(scene, formulation, **options).raw
