"""Bit-rock contact laws for percussive drilling: the interface, its implementations, their Exudyn element.

``LAWS`` maps the scene's ``rock.law`` names to the law classes (:class:`rocklaw.base.RockLaw`).
"""

from rpdrill.rocklaw.base import RockLaw, State, force_and_state
from rpdrill.rocklaw.bilinear import BilinearRock
from rpdrill.rocklaw.catalog import TABLE_1, RockProperties
from rpdrill.rocklaw.jenkins import JenkinsRock

LAWS: dict[str, type[RockLaw]] = {JenkinsRock.name: JenkinsRock, BilinearRock.name: BilinearRock}

__all__ = ["LAWS", "TABLE_1", "BilinearRock", "JenkinsRock", "RockLaw", "RockProperties", "State", "force_and_state"]
