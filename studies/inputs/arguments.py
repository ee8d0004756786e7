"""The arguments of the library's public functions checked as the command line checks its options.

Each kind of argument has one check, ``<kind>_problem(value) -> str | None``: what is wrong with the
value and what is allowed (None: nothing). The library calls :func:`check` at the top of each
public function, which raises :class:`InputError` ``'<function>: <argument>: <problem>'``; the
command line's options use the same checks as argparse types (studies.cli.options), so that the
words are the same: ``rpdrill.run_study: workers: 0: must be a whole number of at least 1`` and
``rpdrill study: error: argument --workers: 0: must be a whole number of at least 1``.
"""

from __future__ import annotations

import math
import os
import re
import socket
from collections.abc import Callable, Iterable, Mapping
from numbers import Real
from typing import Any
from urllib.parse import urlsplit

from ...models.definition.own_code import allowed_modules, module_name_problem
from ...models.definition.validation import InputError, short

WORKERS_PER_CORE = 4  # more workers only share the cores, each holding its own copy of the model
MAX_SEED = 2**32 - 1  # NumPy's legacy seeds and SciPy's rng take 0 .. 2^32 - 1 everywhere
DASK_CONNECT_S = 3.0  # a scheduler that does not answer a TCP connection in this time is not there
Problem = Callable[[Any], "str | None"]


def check(function: str, argument: str, value: Any, *problems: Problem) -> None:
    """InputError '<function>: <argument>: <problem>' for the first of ``problems`` that ``value`` has."""
    for problem in problems:
        why = problem(value)
        if why is not None:
            raise InputError(f"{function}: {argument}: {why}")


def _kind(value: Any) -> str:
    """What ``value`` is, for a message: 'None', 'empty text', 'a dict', 'an int'."""
    if value is None:
        return "None"
    if isinstance(value, str) and not value.strip():
        return "empty text"
    name = type(value).__name__
    return f"{'an' if name[0] in 'aeiou' else 'a'} {name}"


def _whole(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _number(value: Any) -> bool:
    return isinstance(value, Real) and not isinstance(value, bool)


def file_problem(value: Any) -> str | None:
    """A file's path: text or a path-like object, not empty."""
    if isinstance(value, (str, os.PathLike)) and str(value).strip():
        return None
    return f"{short(value)}: give a file's path (text or a pathlib.Path), not {_kind(value)}"


def folder_problem(value: Any) -> str | None:
    """A folder's path: text or a path-like object, not empty."""
    if isinstance(value, (str, os.PathLike)) and str(value).strip():
        return None
    return f"{short(value)}: give a folder's path (text or a pathlib.Path), not {_kind(value)}"


def scene_file_problem(value: Any) -> str | None:
    """A scene file's path (a scene's keys as a mapping are validated with Scene.model_validate)."""
    if file_problem(value) is None:
        return None
    hint = "; a scene's keys as a dict: rpdrill.Scene.model_validate(data)" if isinstance(value, Mapping) else ""
    return f"{short(value)}: give a scene file's path (text or a pathlib.Path) or a rpdrill.Scene, not {_kind(value)}{hint}"


def count_problem(value: Any, least: int = 1) -> str | None:
    """A whole number of at least ``least``."""
    if _whole(value) and value >= least:
        return None
    return f"{short(value)}: must be a whole number of at least {least}"


def workers_problem(value: Any) -> str | None:
    """A number of worker processes: 1 to WORKERS_PER_CORE x the machine's cores."""
    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    why = count_problem(value)
    if why is None and value > most:
        return f"{value}: more than {most} ({WORKERS_PER_CORE} per core of this machine)"
    return why


def seed_problem(value: Any) -> str | None:
    """A random seed: a whole number from 0 to MAX_SEED."""
    if _whole(value) and 0 <= value <= MAX_SEED:
        return None
    return f"{short(value)}: a seed is a whole number from 0 to {MAX_SEED}"


def positive_problem(value: Any) -> str | None:
    """A finite number above zero."""
    if _number(value) and 0 < value < math.inf:
        return None
    return f"{short(value)}: must be a positive number"


def boolean_problem(value: Any) -> str | None:
    return None if isinstance(value, bool) else f"{short(value)}: must be True or False"


def callable_problem(value: Any) -> str | None:
    return None if value is None or callable(value) else f"{short(value)}: give a function or None, not {_kind(value)}"


def choice_problem(allowed: Iterable[str], what: str) -> Problem:
    """One of ``allowed`` (``what`` names the kind: 'formulation')."""
    names = tuple(allowed)

    def problem(value: Any) -> str | None:
        if isinstance(value, str) and value in names:
            return None
        return f"{short(value)}: not a {what}; allowed: {', '.join(names)}"
    return problem


def names_problem(allowed: Iterable[str], what: str) -> Problem:
    """A list of names each one of ``allowed`` (one name alone is a list of one: ``['sandstone']``)."""
    names = tuple(allowed)

    def problem(value: Any) -> str | None:
        if isinstance(value, str):
            return f"{short(value)}: give a list of names, e.g. [{value!r}]"
        if not isinstance(value, (list, tuple)) or not value:
            return f"{short(value)}: give a list of names, e.g. [{names[0]!r}]"
        unknown = [name for name in value if name not in names]
        if unknown:
            return f"{', '.join(map(str, unknown))}: not a {what}; allowed: {', '.join(names)}"
        return None
    return problem


def bounds_problem(value: Any) -> str | None:
    """A mapping of key paths to (low, high): two finite numbers, low below high."""
    if not isinstance(value, Mapping) or not value:
        return f"{short(value)}: give a mapping of key paths to (low, high), e.g. {{'impact.frequency_hz': (45, 70)}}"
    for path, pair in value.items():
        if not isinstance(path, str):
            return f"{short(path)}: a key path is text such as 'impact.frequency_hz'"
        if isinstance(pair, (str, bytes, Mapping)) or not isinstance(pair, Iterable) or len(tuple(pair)) != 2:
            return f"{path}: {short(pair)}: give (low, high), two numbers"
        pair = tuple(pair)
        if not all(_number(bound) and math.isfinite(bound) for bound in pair):
            return f"{path}: {short(pair)}: the bounds must be finite numbers"
        if not pair[0] < pair[1]:
            return f"{path}: {short(pair)}: the lower bound must be below the upper bound"
    return None


def allow_code_problem(value: Any) -> str | None:
    """The modules of one's own a call allows a scene to run (models.definition.own_code): a module name,
    or a list or tuple of them (none: ``()``)."""
    try:
        allowed_modules(value)
    except ValueError as error:
        return str(error)
    return None


# the command line's --allow-code MODULE: one module name (the option repeats)
module_problem = module_name_problem


def rows_problem(value: Any) -> str | None:
    """A results table's rows: a list of mappings of column -> text, each with its 'point'."""
    if isinstance(value, (list, tuple)) and all(isinstance(row, Mapping) and "point" in row for row in value):
        return None
    return f"{short(value)}: give a list of rows (mappings of column -> text, as csv.DictReader reads results.csv)"


def dask_problem(value: Any) -> str | None:
    """A Dask scheduler's address (``tcp://host:port``, ``host:port``), or '' for a LocalCluster."""
    if value is None or value == "":
        return None
    shown = f"{short(value)}: not a Dask scheduler's address; give one such as tcp://127.0.0.1:8786"
    if not isinstance(value, str) or re.search(r"\s", value):
        return shown
    try:
        parts = urlsplit(value if "://" in value else f"tcp://{value}")
        port = parts.port
    except ValueError:
        return shown
    if parts.scheme not in ("tcp", "tls", "inproc", "ucx", "ws", "wss") or not parts.hostname or \
            (parts.scheme != "inproc" and port is None):
        return shown
    return None


def dask_unreachable(value: str) -> str | None:
    """Why no scheduler answers at the address ``value`` (a TCP connection refused or not answered
    within DASK_CONNECT_S), None when something listens there."""
    parts = urlsplit(value if "://" in value else f"tcp://{value}")
    if parts.scheme not in ("tcp", "tls", "ws", "wss"):
        return None
    try:
        with socket.create_connection((parts.hostname, parts.port), timeout=DASK_CONNECT_S):
            return None
    except OSError as error:
        why = f"no answer within {DASK_CONNECT_S:g} s" if isinstance(error, TimeoutError) else \
            error.strerror or str(error)
        return f"{value}: no Dask scheduler answers there ({why}); start one (dask scheduler) or give its address"


def cli_type(problem: Problem, parse: Callable[[str], Any] = str) -> Callable[[str], Any]:
    """An argparse type: the text parsed by ``parse`` (kept as text when it cannot be), then ``problem``;
    argparse prints the problem after the option's name."""
    import argparse

    def convert(text: str) -> Any:
        try:
            value = parse(text)
        except ValueError:
            value = text
        why = problem(value)
        if why is not None:
            raise argparse.ArgumentTypeError(why)
        return value
    convert.__name__ = problem.__name__.removesuffix("_problem")
    return convert


def whole_number(text: str) -> int:
    """A whole number written as one ('12', '-1'); ValueError otherwise."""
    if not re.fullmatch(r"[-+]?[0-9]+", text.strip()):
        raise ValueError(text)
    return int(text)


def number(text: str) -> float:
    """A number as written: a whole number stays one ('-5' is -5, as the library's value shows it)."""
    try:
        return whole_number(text)
    except ValueError:
        return float(text)


def instance_problem(kind: type, what: str, optional: bool = False) -> Problem:
    """An instance of ``kind`` (None too when ``optional``); ``what`` says what to give instead."""
    def problem(value: Any) -> str | None:
        if isinstance(value, kind) or (optional and value is None):
            return None
        return f"{short(value)}: give {what}, not {_kind(value)}"
    return problem


def built_model_problem(value: Any) -> str | None:
    """A built Exudyn model (rpdrill.build_exudyn): an object with the system ``mbs`` and its ``simulation``
    (checked by what it has: Exudyn is not imported to check it)."""
    if hasattr(value, "mbs") and hasattr(value, "simulation"):
        return None
    return f"{short(value)}: give a built model (rpdrill.build_exudyn), not {_kind(value)}"


def either(*problems: Problem) -> Problem:
    """A value that passes one of ``problems`` (the last one's words when it passes none)."""
    def problem(value: Any) -> str | None:
        found = [p(value) for p in problems]
        return None if any(why is None for why in found) else found[-1]
    return problem


def optional(problem: Problem) -> Problem:
    """None, or a value that passes ``problem``."""
    return lambda value: None if value is None else problem(value)


def check_run_options(function: str, workers: Any, out: Any, dask: Any, quiet: Any) -> None:
    """The options every run of many points shares (run_study, calibrate, sensitivity, accuracy, advise):
    ``workers`` (None or a whole number >= 1), ``out`` (None or a folder), ``dask`` (None, "" or an
    address) and ``quiet`` (a boolean), each refused as :func:`check` says."""
    check(function, "workers", workers, optional(workers_problem))
    check(function, "out", out, optional(folder_problem))
    check(function, "dask", dask, dask_problem)
    check(function, "quiet", quiet, boolean_problem)
