"""Strict YAML reading (studies.inputs.reading): what it accepts that YAML 1.1 gets wrong or lets pass, and
that valid files still read as before. Malformed files are in the corpus (tests/test_bad_inputs.py)."""

from __future__ import annotations

import pytest

from rpdrill import InputError
from rpdrill.studies.inputs.reading import parse_yaml, read_yaml


def test_yaml_12_floats_are_numbers():
    data = parse_yaml("a: 1e5\nb: -1.5E-3\nc: 2.0e+9\nd: 100\ne: .5\nf: 1e\ng: 1_000\n", "x.yaml")
    assert data == {"a": 1e5, "b": -1.5e-3, "c": 2e9, "d": 100, "e": 0.5, "f": "1e", "g": 1000}
    assert type(data["a"]) is float and type(data["d"]) is int


def test_merge_keys_byte_order_mark_and_unicode_text_are_read():
    text = "\ufeffbase: &base {k: 1.0, c: 2.0}\nlink:\n  <<: *base\n  c: 3.0\ndescription: Bohrhammer, 65 °C, été\n"
    data = parse_yaml(text, "x.yaml")
    assert data["link"] == {"k": 1.0, "c": 3.0} and data["description"].endswith("été")


@pytest.mark.parametrize("text, fragments", [
    ("a: 1\nb:\n  c: 2\n  c: 3\n", ["b.c (line 4)", "first at line 3"]),
    ("a: {yes: 1}\n", ["a.True (line 1)", "not text"]),
    ("a: 'x\\u200fy'\n", ["a: ", "U+200F", "RIGHT-TO-LEFT MARK"]),
    ("a: [\n", ["line 2", "not valid YAML"]),
])
def test_refusals_name_the_file_the_key_path_and_the_line(text, fragments):
    with pytest.raises(InputError) as error:
        parse_yaml(text.replace("'", '"'), "scene.yaml")
    message = str(error.value)
    assert message.startswith("scene.yaml: ") and all(f in message for f in fragments), message


def test_a_file_with_a_utf8_character_beyond_ascii_reads(tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text("name: bohrgerät\n", encoding="utf-8")
    assert read_yaml(path) == {"name": "bohrgerät"}
