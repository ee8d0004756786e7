"""docs/api.md: its examples (run as printed by the site's build: docs/page_examples.py, docs/conf.py) and every
public name on it, and the study file's keys on docs/studies.md."""

import re
from pathlib import Path

# the study file's schema (its pydantic models) against the page that documents it
UNITS = ("rpdrill.studies.inputs.specs", "rpdrill.studies.scan.study")

ROOT = Path(__file__).resolve().parents[1]
BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "api.md").read_text(encoding="utf-8"), re.DOTALL)


def test_the_page_has_examples():
    assert len(BLOCKS) >= 8


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
