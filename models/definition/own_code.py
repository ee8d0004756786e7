"""Code of one's own that a scene names, and when it may run: a scene is data, and runs no code unasked.

A scene names Python in two places, an extension's ``function`` (models.definition.extensions) and
``rock.law`` (models.definition.rock). Such code runs only when it is

* registered: an installed package declares it under the entry point group ``rpdrill.extensions`` (an
  extension) or ``rpdrill.rock_laws`` (a rock law class), and the scene names it by its registered name
  (``function: clamp``, ``law: rate_dependent``); installing a package is the user's consent, as with
  pytest's plugins; or
* allowed: who reads the scene allows its module for the run, ``--allow-code MODULE`` on the command line or
  ``allow_code=("MODULE",)`` in the library (a module allows its submodules too), and the scene names it
  ``package.module:name``.

The allowance is never read from a scene, study or calibration file: it reaches validation as pydantic's
context (``Scene.model_validate(data, context={"allow_code": ("my_rig",)})``, which every reader of a file
passes), and a validated scene keeps what it was allowed (:func:`allowance`; a private attribute, so that
``Scene.with_``, a pickled scene in a worker process and on Dask keep it). A name that is neither is refused
before anything is imported, naming the module and both ways to allow it (:func:`refusal`). What is found
must then say what it is before anything of it is called or constructed: an extension is marked
(:func:`extension`), a rock law subclasses rocklaw.base.RockLaw. The user's code failing (a module that does
not import, a function or constructor that raises) is the user's: :func:`failure` says so with the user's
file and line (:func:`user_line`).
"""

from __future__ import annotations

import functools
import importlib
import importlib.metadata
import importlib.util
import re
import sys
import traceback
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from pydantic import ValidationInfo

ALLOW_CODE = "allow_code"  # the key of the validation context that carries the allowance
MODULE_NAME = re.compile(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*")
IMPORT_PATH = re.compile(r"[A-Za-z_][\w]*(\.[A-Za-z_][\w]*)*:[A-Za-z_][\w]*(\.[A-Za-z_][\w]*)*")
REGISTERED_NAME = re.compile(r"[A-Za-z_][\w.\-]*")  # an entry point's name (no colon)
EXTENSION_MARK = "__rpdrill_extension__"
SECURITY = "docs/extending.md, \"Security\""


@dataclass(frozen=True)
class Kind:
    """What a scene names: an extension or a rock law, the entry point group of the registered ones and the
    name of what an import path names."""

    what: str
    group: str
    names: str


EXTENSION = Kind("extension", "rpdrill.extensions", "function")
ROCK_LAW = Kind("rock law", "rpdrill.rock_laws", "Class")


def module_name_problem(value: Any) -> str | None:
    """A module a user allows: a dotted Python name (``my_rig``, ``my_rig.clamps``), not an import path."""
    if isinstance(value, str) and MODULE_NAME.fullmatch(value):
        return None
    hint = f"; allow the module {value.partition(':')[0]!r}" if isinstance(value, str) and ":" in value else ""
    return f"{value!r}: not a module name such as 'my_rig' or 'my_rig.clamps'{hint}"


def allowed_modules(value: Any) -> tuple[str, ...]:
    """The modules of an allowance as given (one name, or a list or tuple of names; None: none), sorted, each
    once; ValueError saying what is wrong otherwise."""
    names = [] if value is None else [value] if isinstance(value, str) else \
        list(value) if isinstance(value, (list, tuple, set, frozenset)) else None
    if names is None:
        raise ValueError(f"{value!r}: give module names, e.g. ('my_rig',)")
    for name in names:
        why = module_name_problem(name)
        if why:
            raise ValueError(why)
    return tuple(sorted(set(names)))


def allowance(info: ValidationInfo | None) -> tuple[str, ...]:
    """The modules the reader of a scene allows, from the validation context (none without one)."""
    context = info.context if info is not None else None
    if not isinstance(context, Mapping) or context.get(ALLOW_CODE) is None:
        return ()
    return allowed_modules(context[ALLOW_CODE])


def context(allow_code: Iterable[str] = ()) -> dict[str, tuple[str, ...]]:
    """The validation context that allows ``allow_code``."""
    return {ALLOW_CODE: allowed_modules(tuple(allow_code))}


def is_allowed(module: str, allowed: Sequence[str]) -> bool:
    """Whether ``module`` is one of ``allowed`` or inside one of them (a package allows its submodules)."""
    return any(module == name or module.startswith(name + ".") for name in allowed)


def refusal(module: str, kind: Kind) -> str:
    """Why a scene's import path of a module not allowed is refused, and the ways to allow it."""
    return (f"module {module!r} is code of one's own, which a scene runs only when the user allows it (a scene is "
            f"data): allow it for this run with --allow-code {module} (rpdrill commands) or allow_code=[{module!r}] "
            "(rpdrill.load_scene, load_study, simulate, run_study, calibrate, sensitivity, accuracy, advise, "
            f"crosscheck), or install a package that registers the {kind.what} under the entry point group "
            f"{kind.group!r} and name it by its registered name ({SECURITY})")


# the modules of one's own this process resolved, and what named them: where an error that escaped a run came
# from (:func:`blame_resolved`, the command line's last resort)
RESOLVED: dict[str, str] = {}


@dataclass(frozen=True)
class Found:
    """What a scene's name resolved to: the object, its import path, and the entry point it is registered
    as (``group:name``) with the package (distribution) and version that register it, if it is registered."""

    target: Any
    import_path: str
    entry_point: str | None = None
    package: str | None = None
    version: str | None = None


def resolve(name: str, kind: Kind, allowed: Sequence[str]) -> Found:
    """The object a scene names (module doc): a registered name, or an import path of an allowed module,
    imported only then; ValueError saying why not (a message for the key that names it)."""
    if ":" not in name:
        if not REGISTERED_NAME.fullmatch(name):
            raise ValueError(f"not a registered {kind.what}'s name nor an import path 'package.module:{kind.names}'")
        return _registered(name, kind)
    if not IMPORT_PATH.fullmatch(name):
        raise ValueError(f"not an import path 'package.module:{kind.names}'")
    module_name, _, attribute = name.partition(":")
    if not is_allowed(module_name, allowed):
        raise ValueError(refusal(module_name, kind))
    target: Any = import_own_module(module_name)
    for part in attribute.split("."):
        if not hasattr(target, part):
            raise ValueError(f"module {module_name!r} has no {attribute!r}")
        target = getattr(target, part)
    RESOLVED[module_name] = f"{kind.what} {name}"
    return Found(target, name)


def import_own_module(module_name: str) -> Any:
    """A module of one's own, imported; ValueError naming it and, where it fails on import, the user's
    exception with its file and line."""
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as error:
        if error.name is not None and (module_name + ".").startswith(error.name + "."):
            raise ValueError(f"cannot import module {module_name!r} ({error}); it must be importable where the scene "
                             "runs (installed, or on PYTHONPATH)") from None
        raise ValueError(f"module {module_name!r} failed to import: {failure(error, module_name)}") from None
    except (Exception, SystemExit) as error:  # noqa: BLE001 - the user's module: a syntax error, any exception
        raise ValueError(f"module {module_name!r} failed to import: {failure(error, module_name)}") from None


@functools.cache
def _group(group: str, path: tuple[str, ...], entry_points: Callable[..., Any]) -> tuple[Any, ...]:
    """The entry points of ``group`` on this ``path`` (cached per sys.path: a scene's validation reads them
    at every ``Scene.with_``)."""
    return tuple(entry_points(group=group))


def registered(group: str) -> tuple[Any, ...]:
    """The entry points installed under ``group`` (importlib.metadata)."""
    return _group(group, tuple(sys.path), importlib.metadata.entry_points)


def _registered(name: str, kind: Kind) -> Found:
    points = registered(kind.group)
    chosen = {point.value: point for point in points if point.name == name}
    if not chosen:
        names = ", ".join(sorted({point.name for point in points})) or "none installed"
        raise ValueError(f"no installed package registers a{'n' if kind.what[0] in 'aeiou' else ''} {kind.what} "
                         f"named {name!r} (entry point group {kind.group!r}: {names}); code of one's own is named "
                         f"'package.module:{kind.names}' and its module allowed for the run ({SECURITY})")
    if len(chosen) > 1:
        raise ValueError(f"registered more than once in entry point group {kind.group!r}: "
                         + ", ".join(f"{value} ({_distribution(point)})" for value, point in sorted(chosen.items()))
                         + "; uninstall one of the packages")
    point = next(iter(chosen.values()))
    where = f"entry point {point.value!r} ({_distribution(point)})"
    try:
        import_own_module(point.module)
    except ValueError as error:
        raise ValueError(f"{where}: {error}") from None
    try:
        target = point.load()
    except (Exception, SystemExit) as error:  # noqa: BLE001 - the package's module, the user's code
        raise ValueError(f"{where} does not load: {failure(error, point.module)}") from None
    dist = getattr(point, "dist", None)
    RESOLVED[point.module] = f"{kind.what} {name} ({point.value})"
    return Found(target, point.value, f"{kind.group}:{name}", *((dist.name, dist.version) if dist else ()))


def _distribution(point: Any) -> str:
    dist = getattr(point, "dist", None)
    return f"package {dist.name} {dist.version}" if dist is not None else "an entry point"


CallableT = TypeVar("CallableT", bound=Callable[..., Any])


def extension(function: CallableT | None = None, *, changes_motion: bool = True) -> Any:
    """Mark a function as an extension of the Exudyn model that a scene may name.

    rpdrill calls no callable a scene names that is not marked: not ``os:system``, not a function written for
    something else. The function is called as ``function(model, **parameters)`` on every built model
    (:class:`ExudynModel`), where its module is registered by an installed package (entry point group
    ``rpdrill.extensions``) or allowed by the reader (``allow_code``, ``--allow-code``; docs/extending.md).

    Parameters
    ----------
    function : callable, optional
        The function (``@rpdrill.extension``); without it, the decorator with its options
        (``@rpdrill.extension(changes_motion=False)``).
    changes_motion : bool, default True
        False for an extension that only adds sensors, energy terms or graphics, which the exact and ODE
        formulations may then run without.

    Returns
    -------
    callable
        The function itself, marked; or the decorator.

    Examples
    --------
    >>> import rpdrill
    >>> @rpdrill.extension
    ... def add_sensor(model, name: str = "collar"):
    ...     '''A sensor of the collar's velocity (parameters as the scene gives them).'''
    >>> @rpdrill.extension(changes_motion=False)
    ... def add_graphics(model):
    ...     '''Graphics only: the exact formulation may run without it.'''
    >>> add_graphics.changes_motion
    False
    """
    def mark(target: CallableT) -> CallableT:
        setattr(target, EXTENSION_MARK, True)
        if not changes_motion:
            target.changes_motion = False  # type: ignore[attr-defined]
        return target

    return mark if function is None else mark(function)


def is_extension(target: Any) -> bool:
    """Whether ``target`` is marked as an extension (:func:`extension`)."""
    return callable(target) and getattr(target, EXTENSION_MARK, False) is True


def roots(module_name: str) -> list[Path]:
    """Where the code of a module of one's own lives: its top-level package's folder, or the file of a
    top-level module (found without importing it)."""
    top = module_name.split(".")[0]
    try:
        spec = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        return []
    if spec is None or not spec.origin or spec.origin in ("built-in", "frozen"):
        return []
    origin = Path(spec.origin).resolve()
    return [origin.parent] if spec.submodule_search_locations else [origin]


def user_line(error: BaseException, module_name: str) -> str | None:
    """'file, line N' of the user's code where ``error`` came from: the deepest frame of its traceback in
    the code of ``module_name`` (:func:`roots`), else its deepest frame (a syntax error: where it is)."""
    if isinstance(error, SyntaxError) and error.filename and error.lineno:
        return f"{error.filename}, line {error.lineno}"
    frames = [frame for frame in traceback.extract_tb(error.__traceback__) if not frame.filename.startswith("<")]
    places = roots(module_name)
    mine = [frame for frame in frames if any(_inside(frame.filename, place) for place in places)]
    frame = (mine or frames or [None])[-1]
    return None if frame is None else f"{frame.filename}, line {frame.lineno}"


def _inside(filename: str, place: Path) -> bool:
    path = Path(filename).resolve()
    return path == place or place in path.parents


def failure(error: BaseException, module_name: str) -> str:
    """The user's exception as a message says it: its type, its text and where in the user's code."""
    if isinstance(error, SystemExit):
        text = f"called sys.exit({error.code!r}), which code a scene names must not (raise an exception instead)"
    elif isinstance(error, SyntaxError):
        text = f"SyntaxError: {error.msg}"
    else:  # (a KeyError of a name a model lacks says so as KeyError: models.solvers.exudyn_messages)
        kind = "KeyError" if isinstance(error, KeyError) else type(error).__name__
        try:
            said = str(error)
        except Exception:  # noqa: BLE001 - the user's exception's own text fails: its type says what it is
            said = ""
        text = f"{kind}: {said}" if said else kind
    where = user_line(error, module_name)
    return f"{text} ({where})" if where else text


def named_code(scene: Any) -> dict[str, tuple[str, str]]:
    """The code of one's own a validated scene names: key (``extensions.NAME``, ``rock.law``) -> (its name in
    the scene, its module)."""
    named = {f"extensions.{name}": (extension.function, extension) for name, extension in (scene.extensions or {}).items()}
    if scene.rock.own_law:
        named["rock.law"] = (scene.rock.law, scene.rock)
    modules = {}
    for key, (name, holder) in named.items():
        try:
            modules[key] = (name, holder.found.import_path.partition(":")[0])
        except ValueError:  # (no longer resolves here: nothing of it ran)
            continue
    return modules


def blame(error: BaseException, scene: Any) -> str | None:
    """What a message says of an error raised while ``scene`` ran, when the user's code raised it (a frame of
    its traceback in the code of one the scene names: the deepest such), None otherwise (rpdrill's own)."""
    frames = [frame for frame in traceback.extract_tb(error.__traceback__) if not frame.filename.startswith("<")]
    found = None
    for key, (name, module) in named_code(scene).items():
        places = roots(module)
        depth = max((i for i, frame in enumerate(frames) if any(_inside(frame.filename, p) for p in places)),
                    default=None)
        if depth is not None and (found is None or depth > found[0]):
            found = (depth, key, name, module)
    if found is None:
        return None
    _, key, name, module = found
    return f"{key} ({name}) raised {failure(error, module)}"


def blame_resolved(error: BaseException) -> str | None:
    """What a message says of an error that escaped a command, when the code of one's own this process resolved
    (:data:`RESOLVED`) raised it (the deepest frame of its traceback in that code), None otherwise."""
    frames = [frame for frame in traceback.extract_tb(error.__traceback__) if not frame.filename.startswith("<")]
    found = None
    for module, named in RESOLVED.items():
        places = roots(module)
        depth = max((i for i, frame in enumerate(frames) if any(_inside(frame.filename, p) for p in places)),
                    default=None)
        if depth is not None and (found is None or depth > found[0]):
            found = (depth, module, named)
    return None if found is None else f"the {found[2]} raised {failure(error, found[1])}"
