"""The sections of a scene that say what a run builds and gives: the effects built, the outputs asked for (metrics,
time histories, gauges on wave rods) and the metrics' averaging window (models.definition.scene holds them)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator

from .drill_string import MAX_COUNT, Name, Strict
from .outputs import BODY_METRICS, METRICS, SERIES, body_metric

EFFECTS = ("torsion", "rock_damping", "rock_plasticity", "joint_damping", "indexing")


class Effects(Strict):
    """Which parts of the model are built (the axial impact chain always is).

    In a scene: ``true`` builds an effect, ``false`` leaves it out, a key absent leaves it out
    unless a requested output needs it; no ``effects`` section at all builds every effect the
    scene gives parameters for (the full model); :func:`built_effects` resolves them for a run.
    ``reasons`` is informational (a resolved scene file says there why each effect was built).
    ``rock_plasticity`` off gives an elastic rock that never crushes. ``indexing`` couples rotation
    to penetration (models.drill.indexing): the angle the bit turned between two blows (``rotation`` or the
    torsion line) and the ``bit`` geometry set how each blow meets the rock.
    """

    torsion: bool | None = None
    rock_damping: bool | None = None
    rock_plasticity: bool | None = None
    joint_damping: bool | None = None
    indexing: bool | None = None
    reasons: dict[str, str] = Field(default_factory=dict)


class Gauge(Strict):
    """A strain gauge and accelerometer pair on a wave rod, ``position_m`` from its top (pile-driving analyser
    style: force, velocity, the down- and up-going waves, the energy that passes it per blow)."""

    rod: Name
    position_m: Annotated[float, Field(ge=0)]


class Outputs(Strict):
    """Requested metrics and time histories (time, positions and velocities always come), and gauges on wave rods
    (``gauges: {NAME: {rod: ROD, position_m: X}}``: models.evaluation.wave_readings; gauges alone: the default
    metrics and histories besides).

    No ``outputs`` section: every metric and history of the effects that are built. A list left
    out of a given section is empty.
    """

    metrics: list[str] = Field(default_factory=list)
    timeseries: list[Literal[tuple(SERIES)]] = Field(default_factory=list)  # type: ignore[valid-type]
    gauges: dict[Name, Gauge] = Field(default_factory=dict)

    @field_validator("metrics")
    @classmethod
    def _known_metrics(cls, names: list[str]) -> list[str]:
        for name in names:
            if name not in METRICS and body_metric(name) is None:
                raise ValueError(f"{name!r} is not a metric: one of {', '.join(METRICS)}, or a body's "
                                 f"<body>{', <body>'.join(BODY_METRICS)}")
        return names


class Metrics(Strict):
    """Averaging window: skip ``transient_blows`` blows, then whole blocks of ``block_blows`` blows."""

    transient_blows: Annotated[int, Field(ge=0, le=MAX_COUNT)] = 10
    block_blows: Annotated[int, Field(ge=1, le=MAX_COUNT)] = 5
