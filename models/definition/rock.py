"""The scene's ``rock`` section: a built-in law and its keys, or a law of one's own named by import path.

``law`` is a built-in name (``jenkins``, the paper's Eq. 1, 2; ``bilinear``) whose keys sit directly
under ``rock``, or the import path ``module:Class`` of a class implementing the rock-law interface
(rocklaw.base.RockLaw, docs/extending.md), whose keys go under ``rock.parameters`` and are checked
against its constructor as strictly as a built-in law's (unknown and missing keys, the types of its
annotations: models.definition.extensions.check_parameters). The class is imported by name wherever the
scene runs (a worker process too).
"""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import BaseModel, Field, field_validator, model_validator
from pydantic_core import ValidationError

from ...rocklaw import LAWS, BilinearRock, JenkinsRock, NoRock, RockLaw
from ...rocklaw.base import missing_members
from ...rocklaw.catalog import TABLE_1
from .drill_string import NonNegative, Positive, Strict, _key_error, _problem
from .extensions import IMPORT_PATH, check_parameters, import_object

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


def law_class(law: str) -> type:
    """The class a ``rock.law`` names: a built-in law's, or the class at its import path."""
    return LAWS[law] if law in LAWS else import_object(law)


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

    @field_validator("law")
    @classmethod
    def _built_in_or_import_path(cls, law: str) -> str:
        if law in BUILT_IN_LAWS:
            return law
        if not IMPORT_PATH.fullmatch(law):
            raise ValueError(f"{law!r} is not a built-in law ({', '.join(BUILT_IN_LAWS)}); a law of one's own is named "
                             "by its import path 'package.module:Class' (docs/extending.md)")
        try:
            target = import_object(law)
        except ValueError as error:
            raise ValueError(f"{law!r}: {error}") from None
        if not isinstance(target, type):
            # a ValueError: pydantic reports it as this key's problem
            raise ValueError(f"{law!r} is not a class (a rock law is a class implementing rocklaw.base.RockLaw)")  # noqa: TRY004
        return law

    @property
    def own_law(self) -> bool:
        """Whether ``law`` is a law of one's own (an import path)."""
        return self.law not in BUILT_IN_LAWS

    @model_validator(mode="after")
    def _complete(self) -> Rock:
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
        given = [key for keys in ROCK_LAW_KEYS.values() for key in keys if getattr(self, key) is not None]
        if given:
            raise _key_error("Rock", (given[0],), getattr(self, given[0]), "a key of the built-in laws; the keys of a "
                             "law of one's own go under rock.parameters")
        target = law_class(self.law)
        parameters = check_parameters(target, self.parameters or {}, ("parameters",), "Rock", path=self.law)
        try:
            law = target(**parameters)
        except (TypeError, ValueError) as error:
            raise _key_error("Rock", ("parameters",), self.parameters, "{law} refuses these parameters: {why}",
                             law=self.law, why=str(error)) from None
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
            target = law_class(self.law)
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
