"""The Python-API half of the corpus of misuse (tests/bad_inputs/api_cases.yaml): every call refused
as rpdrill.InputError (or BudgetError) before anything runs, its message naming the argument and
what is allowed, in the words the command line prints for the same option."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import pytest
import yaml
from commands import main

import rpdrill

CORPUS = Path(__file__).resolve().parent / "bad_inputs"
CASES: dict[str, dict] = yaml.safe_load((CORPUS / "api_cases.yaml").read_text(encoding="utf-8"))
SCENE_FILE = CORPUS / "valid" / "drill.yaml"


@functools.cache
def short_result() -> rpdrill.Result:
    scene = rpdrill.load_scene(SCENE_FILE).with_({"solver.end_time_s": 0.05, "metrics.transient_blows": 1,
                                                  "metrics.block_blows": 1})
    return rpdrill.simulate(scene)


def study_file(folder: Path) -> Path:
    path = folder / "study.yaml"
    path.write_text(f"name: misuse\nbase_scene: {SCENE_FILE}\nscan: {{impact.frequency_hz: [50.0, 60.0]}}\n"
                    "metrics: [penetration_rate_m_per_s]\n", encoding="utf-8")
    return path


def resolved(value: Any, places: dict[str, Any]) -> Any:
    if isinstance(value, str) and value in places:
        return places[value] if not callable(places[value]) else places[value]()
    if isinstance(value, list):
        return [resolved(v, places) for v in value]
    if isinstance(value, dict):
        return {k: resolved(v, places) for k, v in value.items()}
    return value


def places(tmp: Path) -> dict[str, Any]:
    return {"$scene": rpdrill.load_scene(SCENE_FILE), "$scene_file": str(SCENE_FILE), "$study_file": str(study_file(tmp)),
            "$out": str(tmp / "out"), "$result": short_result,
            "$tiny_budget": rpdrill.Budget(max_steps=10)}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_library_refuses_misuse_as_the_command_line_does(name, tmp_path, capsys):
    case = CASES[name]
    where = places(tmp_path)
    call = case["call"]
    function = getattr(where["$scene"], call.split(".", 1)[1]) if call.startswith("scene.") else getattr(rpdrill, call)
    error = getattr(rpdrill, case.get("error", "InputError"))
    with pytest.raises(error) as raised:
        function(*resolved(case.get("args", []), where), **resolved(case.get("kwargs", {}), where))
    message = str(raised.value)
    assert type(raised.value) is error and case["word"] in message and "Traceback" not in message, message
    assert not (tmp_path / "out").exists()  # nothing written
    if "cli" in case:
        capsys.readouterr()
        try:
            status = main([str(part) for part in resolved(case["cli"], where)])
        except SystemExit as stop:
            status = stop.code
        printed = capsys.readouterr().err
        assert status == 2 and case["same"] in printed and case["same"] in message, (printed, message)
