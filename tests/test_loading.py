"""Strict YAML reading (studies.inputs.reading): what it accepts that YAML 1.1 gets wrong or lets pass, and
that valid files still read as before. Malformed files are in the corpus (tests/test_bad_inputs.py).
Unit tests of studies.inputs.reading: they import it."""

from __future__ import annotations

import time

import pytest

from rpdrill import InputError
from rpdrill.studies.inputs.reading import parse_yaml, read_yaml

# the strict YAML reader, and the resolved scene file's writer
UNITS = ("rpdrill.studies.inputs.reading", "rpdrill.studies.runtime.output_files")


def test_yaml_12_floats_are_numbers():
    data = parse_yaml("a: 1e5\nb: -1.5E-3\nc: 2.0e+9\nd: 100\ne: .5\nf: 1e\ng: 1_000\n", "x.yaml")
    assert data == {"a": 1e5, "b": -1.5e-3, "c": 2e9, "d": 100, "e": 0.5, "f": "1e", "g": 1000}
    assert type(data["a"]) is float and type(data["d"]) is int


def test_merge_keys_byte_order_mark_and_unicode_text_are_read():
    text = "\ufeffbase: &base {k: 1.0}\nlink:\n  <<: *base\n  c: 3.0\ndescription: Bohrhammer, 65 °C, été\n"
    data = parse_yaml(text, "x.yaml")
    assert data["link"] == {"k": 1.0, "c": 3.0} and data["description"].endswith("été")


@pytest.mark.parametrize("text, fragments", [
    ("a: 1\nb:\n  c: 2\n  c: 3\n", ["b.c (line 4)", "first at line 3"]),
    ("a: {yes: 1}\n", ["a.yes (line 1)", "YAML 1.1 true"]),
    ("a: {1: 1}\n", ["a.1 (line 1)", "not text"]),
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


@pytest.mark.parametrize("value, fragments", [
    ("02500", ["mass_kg (line 1)", "YAML 1.2 reads 2500", "octal 1344", "0o2500"]),
    ("-010", ["mass_kg (line 1)", "octal -8"]),
    ("1:00", ["mass_kg (line 1)", "base-60 number 60"]),
    ("1:30:00.5", ["mass_kg (line 1)", "base-60 number 5400.5"]),
    ("Yes", ["mass_kg (line 1)", "YAML 1.1 true"]),
    ("OFF", ["mass_kg (line 1)", "YAML 1.1 false"]),
    ("!!python/name:os.system x", ["mass_kg (line 1)", "!!python/name:os.system"]),
    ("!!timestamp 2024-01-01", ["mass_kg (line 1)", "!!timestamp"]),
])
def test_values_yaml_11_reads_otherwise_are_refused(value, fragments):
    with pytest.raises(InputError) as error:
        parse_yaml(f"mass_kg: {value}\n", "scene.yaml")
    assert all(f in str(error.value) for f in fragments), str(error.value)


def test_yaml_12_reads_what_both_versions_read_alike_and_quoted_text():
    text = "a: 0o17\nb: 0x1F\nc: '02500'\nd: '1:00'\ne: 'yes'\nf: 2024-01-01\ng: 0\nh: 0.5\ni: !!float 3\n"
    assert parse_yaml(text, "x.yaml") == {"a": 15, "b": 31, "c": "02500", "d": "1:00", "e": "yes", "f": "2024-01-01",
                                          "g": 0, "h": 0.5, "i": 3.0}


@pytest.mark.parametrize("text, fragments", [
    ("s: &s {k: 1}\nb:\n  <<: *s\n  k: 2\n", ["b.k (line 3)", "line 4", "merge key"]),
    ("s: &s {k: 1}\nb:\n  <<: [*s, {k: 3}]\n", ["b.k (line 3)", "two mappings"]),
    ("a: &a {<<: *a}\n", ["recursive alias"]),
    ("%YAML 1.1\n---\na: 1\n", ["line 1", "%YAML 1.1"]),
])
def test_merge_conflicts_and_other_versions_are_refused(text, fragments):
    with pytest.raises(InputError) as error:
        parse_yaml(text, "scene.yaml")
    assert all(f in str(error.value) for f in fragments), str(error.value)


@pytest.mark.parametrize("encoding, bom, named", [
    ("utf-16-le", b"\xff\xfe", "UTF-16 text (little-endian, with a byte-order mark)"),
    ("utf-16-be", b"", "UTF-16 text (big-endian, without a byte-order mark)"),
    ("utf-32-be", b"\x00\x00\xfe\xff", "UTF-32 text (big-endian, with a byte-order mark)"),
    ("utf-32-le", b"", "UTF-32 text (little-endian, without a byte-order mark)"),
])
def test_wide_encodings_are_named(tmp_path, encoding, bom, named):
    path = tmp_path / "scene.yaml"
    path.write_bytes(bom + "name: x\n".encode(encoding))
    with pytest.raises(InputError, match="save the file as UTF-8") as error:
        read_yaml(path)
    assert named in str(error.value)


def test_sizes_are_named_before_the_file_is_read(tmp_path):
    """A 10 MB scene without aliases is refused by its size at once (it took 50 s to be refused as
    'aliases expand ...'); one of more values than an input holds names that count."""
    path = tmp_path / "big.yaml"
    path.write_text("name: big\n" + "".join(f"k{i}: {{mass_kg: {i}.5}}\n" for i in range(500_000)))
    start = time.process_time()
    with pytest.raises(InputError, match=r"\d+ bytes \(\d.* MiB\); an input file is at most 1048576 bytes"):
        read_yaml(path)
    assert time.process_time() - start < 1.0  # a stat, not a read: ~0 s
    path.write_text("name: many\nvalues: [" + ", ".join(["0"] * 30_000) + "]\n")
    with pytest.raises(InputError, match="line 2: more than 20000 values"):
        read_yaml(path)


def test_what_rpdrill_writes_reads_back(tmp_path):
    """A resolved scene as rpdrill writes it (PyYAML quotes every text YAML 1.1 would read otherwise)."""
    from rpdrill.studies.runtime.output_files import write_resolved

    data = {"name": "x", "texts": ["02500", "1:00", "yes", "on", "2024-01-01", "1e5"], "numbers": [1e-5, 2500, 1e300]}
    write_resolved(tmp_path / "r.yaml", data)
    assert read_yaml(tmp_path / "r.yaml") == data


def test_a_text_read_twice_gives_two_independent_mappings():
    """The parse of a text is kept for its next read (studies.inputs.strict_yaml): each read gets its own copy,
    and a refused text is refused again."""
    text = "a: {b: [1.0, 2.0]}\n"
    first = parse_yaml(text, "x.yaml")
    first["a"]["b"].append(3.0)
    assert parse_yaml(text, "x.yaml") == {"a": {"b": [1.0, 2.0]}}
    for _ in range(2):
        with pytest.raises(InputError, match="a.b.c"):
            parse_yaml("a: {b: {c: 1, c: 2}}\n", "x.yaml")
