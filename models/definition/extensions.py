"""Python of one's own named by a scene: extensions of the Exudyn model, and what a run records of them.

A scene's ``extensions`` section names callables, each with its parameters::

    extensions:
      clamp:                                   # a name of the user's choosing
        function: my_rig.clamps:add_clamp      # f(model, **parameters): an allowed module's, or a registered name
        parameters: {mass_kg: 300.0, stiffness_n_per_m: 1.0e9}

A scene is data and runs no code unasked (models.definition.own_code): ``function`` is the name an installed
package registers under the entry point group ``rpdrill.extensions``, or the import path of a callable of a
module its reader allowed for the run; the callable must be marked as an extension (``@rpdrill.extension``).
The Exudyn builder (models.solvers.exudyn_model) calls each on the built model before it runs, in every
process that runs the scene: a worker resolves the callable itself (nothing pickles a built model; the scene
carries its allowance). The parameters are checked here against the callable's signature as strictly as a
scene's own keys (unknown or missing keys, types of the annotations), and ``extensions.NAME.parameters.KEY``
is a key path like any other (``Scene.with_``, scan axes).

An extension changes the motion of the Exudyn model unless its callable says otherwise with the attribute
``changes_motion = False`` (``@rpdrill.extension(changes_motion=False)``: one that only adds sensors, energy
terms or graphics): a scene with an extension that changes the motion runs in the Exudyn formulation only
(the exact and ODE formulations refuse it naming the extension, :func:`refusal`). A rock law of one's own is
named the same way (``rock.law``, models.definition.rock).
"""

from __future__ import annotations

import functools
import importlib.metadata
import inspect
import sys
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    ValidationInfo,
    create_model,
    model_validator,
)

from .drill_string import Strict, _key_error, _problem
from .own_code import EXTENSION, Found, allowance, is_extension, resolve


def package_version(path: str) -> dict[str, str]:
    """The distribution that provides the module of import path ``path`` and its version (importlib.metadata),
    or an empty mapping for a module of no installed distribution (a file on PYTHONPATH)."""
    top = path.partition(":")[0].split(".")[0]
    names = _distributions().get(top, [])
    if not names:
        return {}
    return {"package": names[0], "version": importlib.metadata.version(names[0])}


@functools.cache
def _distributions() -> Mapping[str, list[str]]:
    return importlib.metadata.packages_distributions()


@dataclass(frozen=True)
class CodeRecord:
    """What a run records of one piece of code of one's own it ran (an extension, a rock law): its import path,
    the package and version that provide it (where one does), the file it was loaded from, the entry point it
    is registered as, and an extension's parameters."""

    import_path: str
    package: str | None = None
    version: str | None = None
    file: str | None = None
    entry_point: str | None = None
    parameters: Mapping[str, Any] | None = None

    def as_dict(self) -> dict[str, Any]:
        """As provenance files hold it: the fields that have a value."""
        return {name: value for name, value in vars(self).items() if value is not None}


@dataclass(frozen=True)
class CodeRecords:
    """The code of one's own a run imports: every extension by name and a rock law of one's own."""

    extensions: Mapping[str, CodeRecord] = field(default_factory=dict)
    rock_law: CodeRecord | None = None

    def as_dict(self) -> dict[str, Any]:
        """As provenance files hold it (``extensions``, ``rock_law``: only those there are)."""
        out: dict[str, Any] = {}
        if self.extensions:
            out["extensions"] = {name: record.as_dict() for name, record in self.extensions.items()}
        if self.rock_law is not None:
            out["rock_law"] = self.rock_law.as_dict()
        return out


def record(path: str, found: Found | None = None, parameters: Mapping[str, Any] | None = None) -> CodeRecord:
    """What a run records of the code an import path names: the path and, where it has one, its package and
    version; ``file`` where the module was loaded from; the entry point it is registered as (``found``)."""
    module = sys.modules.get(path.partition(":")[0])
    file = str(module.__file__) if module is not None and getattr(module, "__file__", None) else None
    package = package_version(path)
    entry_point = None
    if found is not None and found.entry_point:
        entry_point = found.entry_point
        package = {"package": found.package, "version": found.version} if found.package else package
    return CodeRecord(path, package.get("package"), package.get("version"), file, entry_point,
                      None if parameters is None else dict(parameters))


STRICT = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, arbitrary_types_allowed=True)


@functools.cache
def signature_model(target: Callable[..., Any], skip: int = 0) -> type[BaseModel]:
    """A strict pydantic model of the keyword parameters of ``target`` (its first ``skip`` positional
    parameters left out): each parameter's annotation (Any without one), required unless it has a default;
    unknown keys are errors unless ``target`` takes ``**kwargs``."""
    parameters = list(inspect.signature(target).parameters.values())[skip:]
    hints: dict[str, Any] = {}
    # a class's annotations resolve in the module of the class that declares each (a dataclass's fields),
    # its __init__'s in its own; one that does not resolve is checked as Any
    for source in ((target, target.__init__) if inspect.isclass(target) else (target,)):
        try:
            hints = {**typing.get_type_hints(source), **hints}
        except (NameError, TypeError):
            continue
    fields: dict[str, Any] = {}
    extra = "forbid"
    for parameter in parameters:
        if parameter.kind is parameter.VAR_KEYWORD:
            extra = "allow"
        elif parameter.kind is not parameter.VAR_POSITIONAL:
            default = ... if parameter.default is parameter.empty else parameter.default
            fields[parameter.name] = (hints.get(parameter.name, Any), default)
    return create_model(f"{getattr(target, '__name__', 'target')}_parameters",
                        __config__=ConfigDict(STRICT, extra=extra), **fields)


def check_parameters(target: Callable[..., Any], parameters: Mapping[str, Any], where: tuple[str, ...],
                     title: str, skip: int = 0, path: str | None = None) -> dict[str, Any]:
    """``parameters`` validated against the signature of ``target`` (:func:`signature_model`); a
    ValidationError at ``where`` + the key otherwise (``title``: the model the error names; ``path``: the
    import path the messages name it by, default its module and name)."""
    model = signature_model(target, skip)
    try:
        validated = model.model_validate(dict(parameters))
    except ValidationError as error:
        details = []
        for item in error.errors():
            if item["type"] == "extra_forbidden":  # what the callable takes, not pydantic's words
                details.append(_problem((*where, *item["loc"]), item["input"], "not a parameter of {name}; its "
                                        "parameters: {names}", name=path or _name(target),
                                        names=", ".join(model.model_fields)))
                continue
            item = {**item, "loc": (*where, *item["loc"])}
            item.pop("url", None)
            if "ctx" in item and "error" in item["ctx"]:  # a validator's exception: pydantic wants its text
                item["ctx"] = {**item["ctx"], "error": str(item["ctx"]["error"])}
            details.append(item)
        raise ValidationError.from_exception_data(title, details) from None
    return {**validated.model_dump(), **(validated.model_extra or {})}


def _name(target: Any) -> str:
    """A callable or class as a message names it: module:qualified name."""
    return f"{getattr(target, '__module__', '?')}:{getattr(target, '__qualname__', repr(target))}"


class Extension(Strict):
    """One Python extension of the Exudyn model (module doc): ``function`` a registered name or 'module:callable'
    of an allowed module, called as ``function(model, **parameters)`` on the built model before it runs."""

    function: str = Field(description="a registered extension's name, or the import path 'package.module:callable' "
                                      "of f(model, **parameters) in a module allowed for the run")
    parameters: dict[str, Any] = Field(default_factory=dict, description="keyword arguments of the callable")
    recorded: dict[str, str] | None = Field(None, description="informational: what the run that wrote a resolved "
                                            "scene imported (import path, package, version, file)")
    _allowed: tuple[str, ...] = PrivateAttr(())  # the modules its reader allowed (models.definition.own_code)

    @model_validator(mode="after")
    def _allowed_marked_and_parameters_fit(self, info: ValidationInfo) -> Extension:
        self._allowed = allowance(info)
        try:
            target = self.found.target
        except ValueError as error:
            raise _key_error("Extension", ("function",), self.function, "{why}", why=str(error)) from None
        if not is_extension(target):
            kind = "a class" if isinstance(target, type) else type(target).__name__
            raise _key_error("Extension", ("function",), self.function, "{kind}, not marked as an rpdrill extension: "
                             "rpdrill calls only a function made to be one, marked with the decorator "
                             "@rpdrill.extension (docs/extending.md, \"Security\")", kind=kind)
        if not _takes_a_model(target):
            raise _key_error("Extension", ("function",), self.function, "takes no model: an extension is called as "
                             "f(model, **parameters), the built model its first argument")
        check_parameters(target, self.parameters, ("parameters",), "Extension", skip=1, path=self.function)
        return self

    @property
    def found(self) -> Found:
        """What ``function`` names, resolved as its reader allowed (models.definition.own_code.resolve);
        ValueError where it may not run or does not resolve."""
        return resolve(self.function, EXTENSION, self._allowed)

    @property
    def target(self) -> Callable[..., Any]:
        """The function ``function`` names."""
        return self.found.target

    @property
    def changes_motion(self) -> bool:
        """False when the callable says it adds nothing the exact and ODE formulations miss
        (``changes_motion = False``: sensors, energy terms, graphics)."""
        return bool(getattr(self.target, "changes_motion", True))

    def apply(self, model: Any) -> None:
        """Call the extension on a built model."""
        self.target(model, **self.parameters)


def _takes_a_model(target: Callable[..., Any]) -> bool:
    """Whether ``target`` takes a first positional argument (the model)."""
    try:
        parameters = list(inspect.signature(target).parameters.values())
    except (TypeError, ValueError):  # no signature to read: called as it is
        return True
    return bool(parameters) and parameters[0].kind in (inspect.Parameter.POSITIONAL_ONLY,
                                                       inspect.Parameter.POSITIONAL_OR_KEYWORD,
                                                       inspect.Parameter.VAR_POSITIONAL)


def refusal(extensions: Mapping[str, Extension] | None, formulation: str) -> tuple[str, str] | None:
    """(the extension's name, why) when ``formulation`` cannot run a scene with these extensions: the exact
    and ODE formulations run no Exudyn items, so an extension that changes the motion is Exudyn's only."""
    if formulation == "exudyn":
        return None
    for name, extension in (extensions or {}).items():
        if extension.changes_motion:
            return name, (f"extension {name!r} ({extension.function}) adds to the Exudyn model, which the {formulation} "
                          "formulation does not build; use solver.formulation exudyn, or, if the extension changes "
                          "nothing of the motion (sensors, energy terms, graphics), mark its callable "
                          "@rpdrill.extension(changes_motion=False) (docs/extending.md)")
    return None


def records(extensions: Mapping[str, Extension] | None) -> dict[str, CodeRecord]:
    """Every extension's record (:func:`record`) with its parameters, by name: what provenance keeps."""
    return {name: record(extension.found.import_path, extension.found, extension.parameters)
            for name, extension in (extensions or {}).items()}
