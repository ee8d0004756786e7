"""Every Python example of docs/api.md runs as written from the root of the checkout."""

import re
from pathlib import Path

import pytest
from doc_examples import Ran, run_examples

# the study file's schema (its pydantic models) against the page that documents it
UNITS = ("rpdrill.studies.inputs.specs", "rpdrill.studies.scan.study")

ROOT = Path(__file__).resolve().parents[1]
BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "api.md").read_text(encoding="utf-8"), re.DOTALL)


def test_the_page_has_examples():
    assert len(BLOCKS) >= 8


@pytest.fixture(scope="module")
def ran() -> list[Ran]:
    """Every example run in order in one fresh process (tests/doc_examples.py)."""
    return run_examples(BLOCKS, ROOT)


@pytest.mark.slow
@pytest.mark.parametrize("index", range(len(BLOCKS)), ids=[f"example{i}" for i in range(len(BLOCKS))])
def test_every_example_runs(ran, index):
    assert not ran[index].failed, ran[index].err
    assert "Traceback" not in ran[index].err, ran[index].err


def test_every_public_name_is_on_the_page():
    import rpdrill

    page = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    assert not [name for name in rpdrill.__all__ if f"`{name}" not in page]


def test_the_study_format_page_names_every_key_of_a_study_file():
    from rpdrill.studies.inputs.specs import Axis
    from rpdrill.studies.scan.study import Plot, StudySpec

    page = (ROOT / "docs" / "studies.md").read_text(encoding="utf-8")
    keys = {field.alias or name for model in (StudySpec, Plot, Axis) for name, field in model.model_fields.items()}
    assert not [key for key in keys - {"values", "start"} if f"`{key}`" not in page]  # a list; from
    assert "`from`" in page or "{from," in page
