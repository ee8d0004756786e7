"""Rock contact laws for percussive drilling: pure functions and their Exudyn element."""

from rocklaw.catalog import TABLE_1, RockProperties
from rocklaw.jenkins import JenkinsRock, force_and_bottom

__all__ = ["TABLE_1", "JenkinsRock", "RockProperties", "force_and_bottom"]
