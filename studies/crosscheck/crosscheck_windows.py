"""Cross-check the Exudyn model against the plain ODE of the paper's Eq. 4 over the first blows.

Both formulations run the scene over a window of ``--blows`` impact periods from the scene's start
(default 20): the Exudyn model with the scene's solver type at ``--step`` (default 5e-6 s; the
differences against the step on the shipped and test drills: docs/crosscheck.md), the ODE
(models.solvers.ode_model) with event-located
rock switches at a tight tolerance. Only a window of early blows is compared: the rock law switches
(contact, crushing) amplify tiny differences from blow to blow, so after many blows two correct
solutions drift apart in phase and a pointwise comparison stops measuring accuracy.

Prints the largest differences of x_n(t), bit velocity and rock force (relative to each signal's
range), of x_n at the window's end, and of every summary metric, with the CPU time of each run.
Exit 0 if x_n at the window's end agrees to 1e-4 and the bit velocity to 1e-3 of its range,
1 if not (or a run failed), 2 for bad input. With ``--out DIR``: DIR/crosscheck.json and an
overlay plot DIR/crosscheck.png.
"""

from __future__ import annotations

from ...models.definition.own_code import ALLOW_CODE
from ...models.definition.scene import Scene
from ..inputs.reading import parse

DEFAULT_STEP_S = 5e-6


def window_scenes(scene: Scene, blows: int, step_s: float, method: str, rtol: float,
                  source: str) -> tuple[Scene, Scene]:
    """The scene ending after ``blows`` periods as (Exudyn at ``step_s`` with the scene's solver type,
    the ODE ``method`` at relative tolerance ``rtol``, absolute tolerance 1e-3 rtol); InputError if invalid."""
    data = scene.model_dump(by_alias=True, exclude_none=True)
    data.pop("outputs", None)  # every output: the comparison needs forces and energies of every step
    window = {"end_time_s": blows * scene.impact.period_s, "output_interval_s": scene.solver.output_interval_s}
    solvers = ({"formulation": "exudyn", "type": scene.solver.type or "rk44", "step_s": step_s},
               {"formulation": "ode", "method": method, "relative_tolerance": rtol, "absolute_tolerance": rtol * 1e-3})
    where = f"{source} (cross-check: --blows {blows}, --step {step_s:g}, --rtol {rtol:g})"
    allowed = {ALLOW_CODE: scene.allowed_code}  # the code of one's own the scene may run
    return tuple(parse(Scene, {**data, "solver": {**window, **solver}}, where, context=allowed) for solver in solvers)


def comparison_table(report: dict, checks: dict) -> str:
    lines = [f"{'quantity':40s} {'ode':>13s} {'exudyn':>13s} {'max |diff|':>11s} {'rel':>9s}"]
    for name, h in report["histories"].items():
        lines.append(f"{name + ' (history)':40s} {'':>13s} {'':>13s} {h['max_abs']:11.3e} {h['max_rel_to_range']:9.2e}")
    b = report["bottom_at_window_end"]
    lines.append(f"{'borehole_bottom_m at window end':40s} {b['reference_m']:13.6e} {b['other_m']:13.6e} "
                 f"{b['abs_m']:11.3e} {b['rel']:9.2e}")
    for name, m in report["metrics"].items():
        lines.append(f"{name:40s} {m['reference']:13.6g} {m['other']:13.6g} {m['abs']:11.3e} {m['rel']:9.2e}")
    cpu = report["cpu_time_s"]
    lines.append(f"{'cpu_time_s':40s} {cpu['ode']:13.4g} {cpu['exudyn']:13.4g}")
    for name, c in checks.items():
        lines.append(f"check {name}: {c['value']:.2e} <= {c['tolerance']:g}: {'pass' if c['passed'] else 'FAIL'}")
    return "\n".join(lines)


