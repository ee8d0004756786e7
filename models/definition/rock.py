"""The scene's ``rock`` section: a built-in law and its keys, or a law of one's own.

``law`` is a built-in name (``jenkins``, the paper's Eq. 1, 2; ``bilinear``) whose keys sit directly
under ``rock``, or a law of one's own (models.definition.own_code: a scene runs no code unasked): the name
an installed package registers under the entry point group ``rpdrill.rock_laws``, or the import path
``module:Class`` of a module its reader allowed for the run. Its class must subclass rocklaw.base.RockLaw
(docs/extending.md), checked before anything of it is constructed; its keys go under ``rock.parameters`` and
are checked against its constructor as strictly as a built-in law's (unknown and missing keys, the types of
its annotations: models.definition.extensions.check_parameters), then the law is built once to check it
(its constructor's own refusals, the interface's members). The class is resolved by name wherever the scene
runs (a worker process too, the scene carrying its allowance).
"""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import BaseModel, Field, PrivateAttr, ValidationInfo, field_validator, model_validator
from pydantic_core import ValidationError

from ...rocklaw import BilinearRock, JenkinsRock, NoRock, RockLaw
from ...rocklaw.base import is_rock_law_class, missing_members
from ...rocklaw.catalog import TABLE_1
from .drill_string import NonNegative, Positive, Strict, _key_error, _problem
from .extensions import CodeRecord, check_parameters, record
from .own_code import IMPORT_PATH, REGISTERED_NAME, ROCK_LAW, Found, allowance, failure, resolve

JENKINS_VALUES = ("stiffness_n_per_m", "damping_n_s_per_m", "threshold_n")
# the keys of each built-in rock law (``law`` itself is common)
ROCK_LAW_KEYS = {
    "jenkins": ("name", "stiffness_n_per_m", "damping_n_s_per_m", "threshold_n", "damping_mode"),
    "bilinear": ("loading_stiffness_n_per_m", "unloading_stiffness_n_per_m"),
    "none": (),  # no rock: the string ends free (rocklaw.free)
}
BUILT_IN_LAWS = tuple(ROCK_LAW_KEYS)


def refuse_foreign_keys(model: BaseModel, what: str, chosen: str, keys: dict[str, tuple[str, ...]],
                        title: str) -> None:
    """A ValidationError for every key of another ``what`` (rock law, formulation) than ``chosen``
    that ``model`` gives, naming the keys ``chosen`` allows."""
    allowed = ", ".join(keys[chosen])
    foreign = [_problem((key,), getattr(model, key), "a key of {what} '{other}', not of '{chosen}'; "
                        "allowed keys here: {allowed}", what=what, other=other, chosen=chosen, allowed=allowed)
               for other, other_keys in keys.items() if other != chosen
               for key in other_keys if key not in keys[chosen] and getattr(model, key) is not None]
    if foreign:
        raise ValidationError.from_exception_data(title, foreign)


class Rock(Strict):
    """The rock under the bit: ``law`` and that law's keys (keys of another law are errors).

    ``jenkins`` (default; the paper's Eq. 1, 2): a Table 1 ``name``, explicit values, or a name
    with overrides; ``damping_mode`` ``contact`` (default) or ``always``. ``bilinear``: loading
    stiffness k_l and unloading stiffness k_u > k_l (rocklaw.bilinear). ``none``: no rock, the string ends
    free (rocklaw.free). ``module:Class``: a law of one's own with its keys in ``parameters`` (module doc).
    """

    law: str = "jenkins"
    name: Literal[tuple(TABLE_1)] | None = None  # type: ignore[valid-type]
    stiffness_n_per_m: Positive | None = None
    damping_n_s_per_m: NonNegative | None = None
    threshold_n: Positive | None = None
    damping_mode: Literal["contact", "always"] | None = None
    loading_stiffness_n_per_m: Positive | None = Field(None, description="bilinear: k_l")
    unloading_stiffness_n_per_m: Positive | None = Field(None, description="bilinear: k_u > k_l")
    parameters: dict[str, Any] | None = Field(None, description="a law of one's own (law: module:Class): its keys")

    _allowed: tuple[str, ...] = PrivateAttr(())  # the modules its reader allowed (models.definition.own_code)

    @field_validator("law")
    @classmethod
    def _built_in_or_named(cls, law: str) -> str:
        """A built-in law, or the form of a law of one's own (resolved by :meth:`_complete`, nothing imported here)."""
        if law in BUILT_IN_LAWS or IMPORT_PATH.fullmatch(law) or (":" not in law and REGISTERED_NAME.fullmatch(law)):
            return law
        raise ValueError(f"{law!r} is not a built-in law ({', '.join(BUILT_IN_LAWS)}); a law of one's own is named by "
                         "the name its package registers (entry point group 'rpdrill.rock_laws') or by its import path "
                         "'package.module:Class' (docs/extending.md)")

    @property
    def own_law(self) -> bool:
        """Whether ``law`` is a law of one's own (an import path)."""
        return self.law not in BUILT_IN_LAWS

    @property
    def found(self) -> Found:
        """The class of a law of one's own, resolved as the scene's reader allowed
        (models.definition.own_code.resolve); ValueError where it may not run or does not resolve."""
        return resolve(self.law, ROCK_LAW, self._allowed)

    def code_record(self) -> CodeRecord:
        """What a run records of a law of one's own (models.definition.extensions.record)."""
        found = self.found
        return record(found.import_path, found)

    @model_validator(mode="after")
    def _complete(self, info: ValidationInfo) -> Rock:
        self._allowed = allowance(info)
        if self.own_law:
            return self._check_own_law()
        if self.parameters is not None:
            raise _key_error("Rock", ("parameters",), self.parameters, "only a law of one's own (law: module:Class) "
                             "takes parameters; the keys of law '{law}' go directly under rock: {keys}",
                             law=self.law, keys=", ".join(ROCK_LAW_KEYS[self.law]))
        refuse_foreign_keys(self, "rock law", self.law, {law: ("law", *keys) for law, keys in ROCK_LAW_KEYS.items()},
                            "Rock")
        if self.law == "bilinear":
            return self._check_bilinear()
        if self.law == "none":
            return self
        if self.name is None:
            missing = [k for k in JENKINS_VALUES if getattr(self, k) is None]
            if missing:
                raise ValueError(f"give a Table 1 name ({', '.join(TABLE_1)}) or all of: {', '.join(missing)}")
        return self

    def _check_bilinear(self) -> Rock:
        for key in ROCK_LAW_KEYS["bilinear"]:
            if getattr(self, key) is None:
                raise _key_error("Rock", (key,), None, "missing: rock law 'bilinear' needs {key}", key=key)
        if self.unloading_stiffness_n_per_m <= self.loading_stiffness_n_per_m:
            raise _key_error("Rock", ("unloading_stiffness_n_per_m",), self.unloading_stiffness_n_per_m,
                             "must be greater than loading_stiffness_n_per_m ({loading})",
                             loading=f"{self.loading_stiffness_n_per_m:g}")
        return self

    def _check_own_law(self) -> Rock:
        try:
            found = self.found
        except ValueError as error:
            raise _key_error("Rock", ("law",), self.law, "{why}", why=str(error)) from None
        if not is_rock_law_class(found.target):
            kind = "a class that does not subclass rocklaw.base.RockLaw" if isinstance(found.target, type) else \
                f"a {type(found.target).__name__}, not a class"
            raise _key_error("Rock", ("law",), self.law, "{kind}: a scene's rock law is a class written as one, "
                             "class MyLaw(RockLaw), and nothing else is constructed (docs/extending.md)", kind=kind)
        given = [key for keys in ROCK_LAW_KEYS.values() for key in keys if getattr(self, key) is not None]
        if given:
            raise _key_error("Rock", (given[0],), getattr(self, given[0]), "a key of the built-in laws; the keys of a "
                             "law of one's own go under rock.parameters")
        target = found.target
        parameters = check_parameters(target, self.parameters or {}, ("parameters",), "Rock", path=self.law)
        module = found.import_path.partition(":")[0]
        try:
            law = target(**parameters)
        except (TypeError, ValueError) as error:
            raise _key_error("Rock", ("parameters",), self.parameters, "{law} refuses these parameters: {why}",
                             law=self.law, why=failure(error, module)) from None
        except (Exception, SystemExit) as error:  # noqa: BLE001 - the user's constructor: its error is the user's
            raise _key_error("Rock", ("law",), self.law, "the law's constructor failed: {why}",
                             why=failure(error, module)) from None
        missing = missing_members(law)
        if missing:
            raise _key_error("Rock", ("law",), self.law, "not a rock law: it lacks {missing} of the interface "
                             "rocklaw.base.RockLaw (docs/extending.md)", missing=", ".join(missing))
        return self

    def completed(self) -> Rock:
        """This rock with every value of its law filled in: a Jenkins rock's Table 1 values where a
        named rock gives none, and damping_mode ``contact`` (a new object; the scene is not changed)."""
        if self.law != "jenkins":
            return self
        row = TABLE_1[self.name] if self.name else None
        filled = {key: getattr(row, key) for key in JENKINS_VALUES if getattr(self, key) is None}
        return self.model_copy(update={**filled, "damping_mode": self.damping_mode or "contact"})

    def build(self, damping: bool = True, plasticity: bool = True, indexed: bool = False) -> RockLaw:
        """The law; without ``damping`` no rock damper, without ``plasticity`` an elastic rock at the
        loading stiffness (Jenkins: F_th infinite; bilinear: k_u = k_l); ``indexed`` (under an indexing
        model): a Jenkins rock with the blow's threshold as a state (rocklaw.jenkins). A law of one's own
        is built from its parameters as given (the scene refuses the effects that would change it)."""
        if self.own_law:
            target = self.found.target
            return target(**check_parameters(target, self.parameters or {}, ("parameters",), "Rock"))
        rock = self.completed()
        if rock.law == "none":
            return NoRock()
        if rock.law == "bilinear":
            loading = rock.loading_stiffness_n_per_m
            return BilinearRock(loading, rock.unloading_stiffness_n_per_m if plasticity else loading)
        return JenkinsRock(rock.stiffness_n_per_m, rock.damping_n_s_per_m if damping else 0.0,
                           rock.threshold_n if plasticity else math.inf, rock.damping_mode,
                           indexed=indexed and plasticity)
