"""Bit-rock contact laws for percussive drilling: the interface, its implementations, their Exudyn element.

``LAWS`` maps the scene's ``rock.law`` names to the law classes (:class:`rocklaw.base.RockLaw`).
"""

from .base import RockLaw, State, force_and_state
from .bilinear import BilinearRock
from .catalog import TABLE_1, RockProperties
from .free import NoRock
from .jenkins import JenkinsRock

LAWS: dict[str, type[RockLaw]] = {JenkinsRock.name: JenkinsRock, BilinearRock.name: BilinearRock, NoRock.name: NoRock}

__all__ = ["LAWS", "TABLE_1", "BilinearRock", "JenkinsRock", "NoRock", "RockLaw", "RockProperties", "State",
           "force_and_state"]
