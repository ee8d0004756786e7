"""Bit-rock contact laws for percussive drilling: the interface, its implementations, their Exudyn element.

``LAWS`` maps the scene's ``rock.law`` names to the law classes (:class:`rocklaw.base.RockLaw`).
"""

from .base import RockLaw, State, force_and_state
from .bilinear import BilinearRock
from .catalog import TABLE_1, RockProperties
from .free import NoRock
from .jenkins import JenkinsRock

#: The rock laws by the names a scene's ``rock.law`` takes: ``jenkins`` (:class:`JenkinsRock`, the paper's
#: Eq. 1, 2), ``bilinear`` (:class:`BilinearRock`) and ``none`` (:class:`NoRock`: a string that ends free, no
#: rock below it). A law of one's own is named by its import path or by the name its package registers (entry
#: point group ``rpdrill.rock_laws``), not here.
LAWS: dict[str, type[RockLaw]] = {JenkinsRock.name: JenkinsRock, BilinearRock.name: BilinearRock, NoRock.name: NoRock}

__all__ = ["LAWS", "TABLE_1", "BilinearRock", "JenkinsRock", "NoRock", "RockLaw", "RockProperties", "State",
           "force_and_state"]
