"""What a run's evaluation reads of the prepared scene it came from: the interface that
models.solvers.simulation.Simulation provides (the results, metrics, energy account and stability
checks read these and nothing else, so they name this interface, not the solvers' class)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from ...rocklaw import RockLaw
    from ..definition.scene import Outputs, Scene, Torsion
    from ..drill.chain import AxialChain
    from ..drill.piston import PistonSetup
    from .solver_settings import Settings


class PreparedRun(Protocol):
    """A scene prepared for a run (models.solvers.simulation.Simulation)."""

    scene: Scene
    outputs: Outputs
    chain: AxialChain
    rock: RockLaw
    settings: Settings
    piston: PistonSetup | None

    @property
    def dynamic_chain(self) -> AxialChain: ...

    @property
    def name(self) -> str: ...

    @property
    def torsion(self) -> Torsion | None: ...

    @property
    def needed_data(self) -> frozenset[str]: ...

    @property
    def spectral_radius_per_s(self) -> float | None: ...

    def resolved_scene(self) -> dict[str, Any]: ...
