"""How every metric, time history and scene parameter is shown: its name, symbol, display unit and
scale. Plots, tables and printed summaries take their labels from here; the data stay in SI units.

A display value is the SI value times ``scale`` (0.00035 m per blow at scale 1e3 is 0.35 mm per blow).
Metrics are keyed by the names of models.definition.outputs.METRICS, time histories by their column names
(models.evaluation.results.SimulationResult.columns, ``*`` for a body's name), parameters by dotted scene
paths (``*`` for a name in drill_string.bodies or drill_string.connectors, filled into the name).
A parameter without a unit (``unit=""``) is categorical (a rock name, a solver type) and is
never a plot axis. ``merit`` marks the figures of merit, larger is better, whose optima a study
reports (studies.scan.study_optima).
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, replace
from typing import Any

from ...models.definition.scene import Scene


@dataclass(frozen=True)
class Quantity:
    """One displayed quantity: ``name``, ``symbol`` (matplotlib mathtext, without $), ``unit`` and
    ``scale`` (display value = SI value x scale), the SI unit, and whether it is a figure of merit."""

    name: str
    symbol: str
    unit: str
    scale: float = 1.0
    si_unit: str = ""
    merit: bool = False

    @property
    def categorical(self) -> bool:
        return not self.unit

    def label(self) -> str:
        """Plot label: 'penetration rate $v_p$ [mm/s]'."""
        symbol = f" ${self.symbol}$" if self.symbol else ""
        return f"{self.name}{symbol}" + (f" [{self.unit}]" if self.unit else "")

    def heading(self) -> str:
        """Plain-text column heading: 'penetration rate [mm/s]'."""
        return self.name + (f" [{self.unit}]" if self.unit else "")

    def display(self, value: float) -> float:
        return value * self.scale

    def show(self, value: Any, digits: int = 4) -> str:
        """A value in display units without the unit ('0.35'); text as it is."""
        if isinstance(value, str) or self.categorical:
            return str(value)
        return f"{self.display(float(value)):.{digits}g}"

    def show_with_unit(self, value: Any, digits: int = 4) -> str:
        """'0.35 mm/blow', 'sandstone'."""
        return self.show(value, digits) + (f" {self.unit}" if self.unit and not isinstance(value, str) else "")


def _q(name: str, symbol: str, unit: str, scale: float = 1.0, si_unit: str = "", merit: bool = False) -> Quantity:
    return Quantity(name, symbol, unit, scale, si_unit or unit, merit)


def _category(name: str) -> Quantity:
    return Quantity(name, "", "")


# SI -> display: velocities of the bit in m/s, the slow penetration in mm/s, forces in kN,
# stiffnesses in MN/m, dampings in kN s/m.
METRICS: dict[str, Quantity] = {
    "penetration_rate_m_per_s": _q("penetration rate", "v_p", "mm/s", 1e3, "m/s", merit=True),
    "penetration_rate_block_std_m_per_s": _q("penetration rate spread over blocks", r"\sigma_{v_p}", "mm/s", 1e3, "m/s"),
    "penetration_rate_block_min_m_per_s": _q("penetration rate, slowest block", r"v_{p,min}", "mm/s", 1e3, "m/s"),
    "penetration_rate_block_max_m_per_s": _q("penetration rate, fastest block", r"v_{p,max}", "mm/s", 1e3, "m/s"),
    "penetration_per_impact_energy_m_per_j": _q("penetration per impact energy", r"v_p / P_d", "mm/kJ", 1e6, "m/J",
                                                merit=True),
    "advance_per_blow_m": _q("advance per blow", r"\Delta x_n", "mm/blow", 1e3, "m/blow", merit=True),
    "advance_per_blow_std_m": _q("advance per blow, spread", r"\sigma_{\Delta x_n}", "mm/blow", 1e3, "m/blow"),
    "borehole_bottom_final_m": _q("borehole bottom at the end", "x_n", "mm", 1e3, "m"),
    "bit_velocity_peak_m_per_s": _q("peak bit velocity", r"\hat{v}_3", "m/s", merit=True),
    "bit_velocity_rms_m_per_s": _q("RMS bit velocity", r"\tilde{v}_3", "m/s", merit=True),
    "collar_velocity_peak_m_per_s": _q("peak collar velocity", r"\hat{v}_2", "m/s", merit=True),
    "collar_velocity_rms_m_per_s": _q("RMS collar velocity", r"\tilde{v}_2", "m/s", merit=True),
    "rock_force_max_n": _q("peak rock force", r"\hat{F}_r", "kN", 1e-3, "N"),
    "impact_energy_j": _q("impact work in the window", "W_d", "J"),
    "feed_energy_j": _q("feed work in the window", "W_f", "J"),
    "crushing_work_j": _q("crushing work in the window", "W_c", "J"),
    "energy_transfer_efficiency": _q("energy transfer efficiency", r"\eta", "%", 100.0, "1", merit=True),
    "energy_balance_relative_error": _q("energy balance error", r"\epsilon_E", "%", 100.0, "1"),
    "piston_rebound_energy_j": _q("piston rebound energy per blow", r"E_{reb}", "J"),
    "rod_stress_max_pa": _q("largest rod stress", r"\hat{\sigma}", "MPa", 1e-6, "Pa"),
    "rock_energy_per_blow_j": _q("rock energy per blow", r"W_r", "J"),
    "rock_transfer_efficiency": _q("energy transfer to the rock", r"\eta_r", "%", 100.0, "1", merit=True),
    "penetration_per_blow_energy_m_per_j": _q("penetration per blow energy", r"v_p / (E_{blow} f)", "mm/kJ", 1e6,
                                              "m/J", merit=True),
    "window_start_s": _q("averaging window start", "t_0", "s"),
    "window_end_s": _q("averaging window end", "t_1", "s"),
    "window_blows": _q("blows averaged", "N", "blows"),
    "cpu_time_s": _q("CPU time", r"t_{CPU}", "s"),
}

SERIES: dict[str, Quantity] = {
    "time_s": _q("time", "t", "s"),
    "*_position_m": _q("{name} position", "x", "mm", 1e3, "m"),
    "*_velocity_m_per_s": _q("{name} velocity", "v", "m/s"),
    "borehole_bottom_m": _q("borehole bottom", "x_n", "mm", 1e3, "m"),
    "rock_force_n": _q("rock force", "F_r", "kN", 1e-3, "N"),
    "impact_force_n": _q("impact force", "F_d", "kN", 1e-3, "N"),
    "torsion_angle_rad": _q("torsion angle", r"\varphi", "rad"),
    "torsion_rate_rad_per_s": _q("torsion rate", r"\dot{\varphi}", "rad/s"),
    "piston_contact_force_n": _q("piston contact force", "F_c", "kN", 1e-3, "N"),
    "piston_velocity_m_per_s": _q("piston velocity", "v_{piston}", "m/s"),
    "*_force_n": _q("{name} force (compression)", "F", "kN", 1e-3, "N"),
    "*_compression_m": _q("{name} compression", r"\delta", "mm", 1e3, "m"),
    "*_gap_opening_m": _q("{name} gap opening", "g", "mm", 1e3, "m"),
    "*_top_stress_pa": _q("{name} stress at its top (compression)", r"\sigma", "MPa", 1e-6, "Pa"),
    "*_bottom_stress_pa": _q("{name} stress at its bottom (compression)", r"\sigma", "MPa", 1e-6, "Pa"),
}
# a body's metrics by its name (models.definition.outputs.BODY_METRICS)
BODY_METRICS: dict[str, Quantity] = {
    "*_velocity_peak_m_per_s": _q("peak {name} velocity", r"\hat{v}", "m/s", merit=True),
    "*_velocity_rms_m_per_s": _q("RMS {name} velocity", r"\tilde{v}", "m/s", merit=True),
    "*_compressive_stress_max_pa": _q("largest compressive stress in {name}", r"\hat{\sigma}_c", "MPa", 1e-6, "Pa"),
    "*_tensile_stress_max_pa": _q("largest tensile stress in {name}", r"\hat{\sigma}_t", "MPa", 1e-6, "Pa"),
    "*_energy_in_per_blow_j": _q("energy into {name} per blow", r"E_{in}", "J"),
    "*_energy_out_per_blow_j": _q("energy out of {name} per blow", r"E_{out}", "J"),
}

PARAMETERS: dict[str, Quantity] = {
    "name": _category("scene"),
    "description": _category("description"),
    "drill_string.bodies.*.mass_kg": _q("{name} mass", "m", "kg"),
    "drill_string.bodies.*.length_m": _q("{name} length", "L", "m"),
    "drill_string.bodies.*.diameter_m": _q("{name} diameter", "D", "mm", 1e3, "m"),
    "drill_string.bodies.*.bore_diameter_m": _q("{name} bore diameter", "d", "mm", 1e3, "m"),
    "drill_string.bodies.*.mass_per_length_kg_per_m": _q("{name} mass per length", "m'", "kg/m"),
    "drill_string.bodies.*.youngs_modulus_pa": _q("{name} Young's modulus", "E", "GPa", 1e-9, "Pa"),
    "drill_string.bodies.*.density_kg_per_m3": _q("{name} density", r"\rho", "kg/m³"),
    "drill_string.bodies.*.segments": _q("{name} segments", "N", "segments"),
    "drill_string.bodies.*.model": _category("{name} model"),
    "drill_string.bodies.*.sn_curve.stress_amplitude_pa": _q("{name} S-N reference amplitude", "S_{ref}", "MPa", 1e-6,
                                                             "Pa"),
    "drill_string.bodies.*.sn_curve.cycles": _q("{name} S-N reference cycles", "N_{ref}", "cycles"),
    "drill_string.bodies.*.sn_curve.exponent": _q("{name} S-N exponent", "m", "1"),
    "drill_string.bodies.*.sn_curve.endurance_limit_pa": _q("{name} endurance limit", "S_e", "MPa", 1e-6, "Pa"),
    "drill_string.connectors.*.type": _category("{name} type"),
    "drill_string.connectors.*.from": _category("{name} from"),
    "drill_string.connectors.*.to": _category("{name} to"),
    "drill_string.connectors.*.stiffness_n_per_m": _q("{name} stiffness", "k", "MN/m", 1e-6, "N/m"),
    "drill_string.connectors.*.damping_n_s_per_m": _q("{name} damping", "c", "kN s/m", 1e-3, "N s/m"),
    "drill_string.connectors.*.gap_m": _q("{name} gap", "g", "mm", 1e3, "m"),
    "drill_string.connectors.*.sleeve_length_m": _q("{name} sleeve length", "L_s", "mm", 1e3, "m"),
    "drill_string.connectors.*.sleeve_outer_diameter_m": _q("{name} sleeve outer diameter", "D_s", "mm", 1e3, "m"),
    "drill_string.impact_body": _category("impact body"),
    "drill_string.rock_body": _category("rock body"),
    "torsion.inertia_kg_m2": _q("torsion inertia", "J", "kg m²"),
    "torsion.stiffness_n_m_per_rad": _q("torsion stiffness", "k_x", "kN m/rad", 1e-3, "N m/rad"),
    "torsion.damping_n_m_s_per_rad": _q("torsion damping", "c_x", "N m s/rad"),
    "torsion.drive_torque_n_m": _q("drive torque", "M_x", "N m"),
    "torsion.resisting_torque_n_m": _q("resisting torque", "M_c", "N m"),
    "feed.force_n": _q("feed force", r"F_{dt}", "kN", 1e-3, "N"),
    "feed.acts_on": _category("feed acts on"),
    "impact.amplitude_n": _q("impact amplitude", "I", "kN", 1e-3, "N"),
    "impact.frequency_hz": _q("impact frequency", "f", "Hz"),
    "impact.shape": _category("pulse shape"),
    "impact.duration_s": _q("pulse duration", r"\tau", "ms", 1e3, "s"),
    "impact.piston.mass_kg": _q("piston mass", "m_p", "kg"),
    "impact.piston.length_m": _q("piston length", "L_p", "m"),
    "impact.piston.diameter_m": _q("piston diameter", "D_p", "mm", 1e3, "m"),
    "impact.piston.bore_diameter_m": _q("piston bore diameter", "d_p", "mm", 1e3, "m"),
    "impact.piston.mass_per_length_kg_per_m": _q("piston mass per length", "m'_p", "kg/m"),
    "impact.piston.youngs_modulus_pa": _q("piston Young's modulus", "E_p", "GPa", 1e-9, "Pa"),
    "impact.piston.density_kg_per_m3": _q("piston density", r"\rho_p", "kg/m³"),
    "impact.piston.segments": _q("piston segments", "N_p", "segments"),
    "impact.piston.sn_curve.stress_amplitude_pa": _q("piston S-N reference amplitude", "S_{ref}", "MPa", 1e-6, "Pa"),
    "impact.piston.sn_curve.cycles": _q("piston S-N reference cycles", "N_{ref}", "cycles"),
    "impact.piston.sn_curve.exponent": _q("piston S-N exponent", "m", "1"),
    "impact.piston.sn_curve.endurance_limit_pa": _q("piston endurance limit", "S_e", "MPa", 1e-6, "Pa"),
    "impact.piston.model": _category("piston model"),
    "impact.piston.velocity_m_per_s": _q("strike speed", "v_p", "m/s"),
    "impact.piston.energy_j": _q("blow energy", r"E_{blow}", "J"),
    "impact.piston.contact_stiffness_n_per_m": _q("piston contact stiffness", "k_c", "MN/m", 1e-6, "N/m"),
    "rock.law": _category("rock law"),
    "rock.parameters": _category("rock law parameters"),  # each by its key: _own_parameter
    "extensions.*.function": _category("{name} extension"),
    "extensions.*.parameters": _category("{name} parameters"),  # each by its key: _own_parameter
    "extensions.*.recorded": _category("{name} as recorded"),
    "rock.name": _category("rock"),
    "rock.stiffness_n_per_m": _q("rock stiffness", "k_n", "MN/m", 1e-6, "N/m"),
    "rock.damping_n_s_per_m": _q("rock damping", "c_n", "kN s/m", 1e-3, "N s/m"),
    "rock.threshold_n": _q("crushing threshold", r"F_{th}", "kN", 1e-3, "N"),
    "rock.damping_mode": _category("rock damping mode"),
    "rock.loading_stiffness_n_per_m": _q("rock loading stiffness", "k_l", "MN/m", 1e-6, "N/m"),
    "rock.unloading_stiffness_n_per_m": _q("rock unloading stiffness", "k_u", "MN/m", 1e-6, "N/m"),
    "bit.diameter_m": _q("bit diameter", "D", "mm", 1e3, "m"),
    "bit.gauge_button_diameter_m": _q("gauge button diameter", "d", "mm", 1e3, "m"),
    "bit.gauge_buttons": _q("gauge buttons", "N", "buttons"),
    "bit.crater_width_m": _q("crater width", "w", "mm", 1e3, "m"),
    "rotation.speed_rpm": _q("rotation speed", "n", "rpm"),
    "solver.formulation": _category("formulation"),
    "solver.preset": _category("accuracy preset"),
    "solver.steady_state": _category("steady state"),
    "solver.end_time_s": _q("end time", r"t_{end}", "s"),
    "solver.output_interval_s": _q("output interval", r"\Delta t_{out}", "ms", 1e3, "s"),
    "solver.type": _category("solver"),
    "solver.step_s": _q("solver step", "h", "µs", 1e6, "s"),
    "solver.spectral_radius": _q("spectral radius", r"\rho_\infty", "-", si_unit="1"),
    "solver.relative_tolerance": _q("relative tolerance", "rtol", "-", si_unit="1"),
    "solver.absolute_tolerance": _q("absolute tolerance", "atol", "SI"),
    "solver.method": _category("ODE method"),
    "solver.sample_interval_s": _q("sample interval", r"\Delta t_s", "µs", 1e6, "s"),
    "solver.min_switch_interval_s": _q("shortest mode", r"\Delta t_{min}", "s"),
    "solver.max_switches_per_blow": _q("switches per blow allowed", "", "switches/blow"),
    "solver.wave_step_s": _q("wave step", r"h_w", "µs", 1e6, "s"),
    "metrics.transient_blows": _q("transient blows", "", "blows"),
    "metrics.block_blows": _q("blows per block", "", "blows"),
    "effects.torsion": _category("torsion"),
    "effects.rock_damping": _category("rock damping"),
    "effects.rock_plasticity": _category("rock plasticity"),
    "effects.joint_damping": _category("joint damping"),
    "effects.indexing": _category("bit indexing"),
    "effects.reasons": _category("effect reasons"),
    "outputs.metrics": _category("metrics asked for"),
    "outputs.timeseries": _category("histories asked for"),
    "outputs.gauges.*.rod": _category("{name} gauge's rod"),
    "outputs.gauges.*.position_m": _q("{name} gauge position", "x_g", "m"),
    "start": _category("start"),
}


def _named(found: Quantity, name: str) -> Quantity:
    return replace(found, name=found.name.format(name=name))


def _matched(entries: dict[str, Quantity], key: str) -> Quantity | None:
    """The entry of ``key``, or of the pattern '*<suffix>' it matches, named after the part it names."""
    if key in entries:
        return entries[key]
    for pattern, found in entries.items():
        suffix = pattern.removeprefix("*")
        if pattern.startswith("*") and key.endswith(suffix) and len(key) > len(suffix):
            return _named(found, key.removesuffix(suffix))
    return None


def metric(name: str) -> Quantity:
    """The catalogue entry of a metric, a body's by its name too (KeyError for a metric without one)."""
    found = METRICS.get(name) or _matched(BODY_METRICS, name)
    if found is None:
        raise KeyError(name)
    return found


def series(column: str) -> Quantity:
    """The entry of a time-history column ('bit_velocity_m_per_s': the velocity of the body 'bit')."""
    found = _matched(SERIES, column)
    if found is None:
        raise KeyError(f"studies.display.catalogue has no time history {column!r}")
    return found


# the SI unit of a key of one's own (an extension's or a rock law's parameter) by its name's ending, longest first
UNIT_SUFFIXES = (("_n_s_per_m", "N s/m"), ("_n_m_per_rad", "N m/rad"), ("_n_per_m", "N/m"), ("_kg_m2", "kg m²"),
                 ("_kg", "kg"), ("_m_per_s", "m/s"), ("_hz", "Hz"), ("_rpm", "rpm"), ("_pa", "Pa"), ("_j", "J"),
                 ("_n", "N"), ("_m", "m"), ("_s", "s"))


def _own_parameter(path: str) -> Quantity | None:
    """A parameter of one's own (``extensions.NAME.parameters.KEY``, ``rock.parameters.KEY``): its key as its
    name (and the extension's), SI units read off the key's ending (none: a number without a unit)."""
    parts = path.split(".")
    if len(parts) == 4 and parts[0] == "extensions" and parts[2] == "parameters":
        owner = f" ({parts[1]})"
    elif len(parts) == 3 and parts[:2] == ["rock", "parameters"]:
        owner = " (rock)"
    else:
        return None
    key = parts[-1]
    unit = next((unit for suffix, unit in UNIT_SUFFIXES if key.endswith(suffix)), "-")
    name = key.removesuffix(next((suffix for suffix, _ in UNIT_SUFFIXES if key.endswith(suffix)), ""))
    return _q(name.replace("_", " ") + owner, "", unit, si_unit=unit)


def parameter(path: str) -> Quantity:
    """The entry of a dotted scene path ('drill_string.bodies.collar.mass_kg': 'collar mass'; a parameter of
    one's own by its key, :func:`_own_parameter`)."""
    if path in PARAMETERS:
        return PARAMETERS[path]
    own = _own_parameter(path)
    if own is not None:
        return own
    parts = path.split(".")
    for i, name in enumerate(parts):
        pattern = ".".join([*parts[:i], "*", *parts[i + 1:]])
        if pattern in PARAMETERS:
            return _named(PARAMETERS[pattern], name)
    raise KeyError(f"studies.display.catalogue has no scene parameter {path!r}")


def quantity(key: str) -> Quantity:
    """A metric or a scene parameter, whichever ``key`` names."""
    return METRICS[key] if key in METRICS else parameter(key)


def _shown(scene: Scene, path: str, varied: Collection[str], text: str = "{}") -> list[str]:
    """``text`` with the value of ``path`` in display units ('500 MN/m'), or nothing if it is ``varied``."""
    if path in varied:
        return []
    node: Any = scene
    for part in path.split("."):
        node = getattr(node, part)
    return [text.format(parameter(path).show_with_unit(node, 3))]


def describe_scene(scene: Scene, varied: Collection[str] = ()) -> str:
    """The scene, its rock, impact, feed and extensions in one line for a title, leaving out the ``varied``
    paths: 'paper_base: rock sandstone (k_n 510 MN/m, F_th 210 kN), impact 220 kN half-sine of 1.6 ms at 65 Hz,
    feed 75 kN'."""
    rock = scene.rock.completed()
    filled = scene.model_copy(update={"rock": rock})
    if "rock.name" in varied:
        rock_text = "rock varied"
    elif rock.own_law:
        rock_text = f"rock law {rock.law}"
    else:
        symbols = {"stiffness_n_per_m": "k_n", "threshold_n": "F_th", "loading_stiffness_n_per_m": "k_l",
                   "unloading_stiffness_n_per_m": "k_u"}
        values = [v for key, symbol in symbols.items() if getattr(rock, key, None) is not None
                  for v in _shown(filled, f"rock.{key}", varied, f"{symbol} {{}}")]
        rock_text = " ".join(["rock"] + ([rock.name] if rock.name else []) + ([f"({', '.join(values)})"] if values else
                                                                             [] if rock.name else ["varied"]))
    if scene.impact.piston is not None:  # 'piston 4.5 kg at 9 m/s, 60 Hz'
        piston = scene.impact.piston
        size = ["impact.piston.mass_kg"] if piston.mass_kg is not None else ["impact.piston.length_m"]
        strike = "impact.piston.velocity_m_per_s" if piston.velocity_m_per_s is not None else "impact.piston.energy_j"
        impact = " ".join(["piston", *[v for p in size for v in _shown(scene, p, varied)],
                           *_shown(scene, strike, varied, "at {}"), *_shown(scene, "impact.frequency_hz", varied, "{}")])
    else:
        impact = " ".join(["impact", *_shown(scene, "impact.amplitude_n", varied), scene.impact.shape.replace("_", "-"),
                           *_shown(scene, "impact.duration_s", varied, "of {}"),
                           *_shown(scene, "impact.frequency_hz", varied, "at {}")])
    extensions = [f"extension {name} ({extension.function})" for name, extension in (scene.extensions or {}).items()]
    return f"{scene.name}: " + ", ".join([rock_text, impact, *_shown(scene, "feed.force_n", varied, "feed {}"),
                                          *extensions])
