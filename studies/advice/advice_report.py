"""What ``rpdrill advise`` prints and writes, in display units (studies.display.catalogue): the best point
and the curves around it as text, the table of best points in Markdown (docs/advice.md is one,
with the command that made it), and the JSON record (SI units)."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..display.catalogue import metric, parameter
from ..display.text_tables import markdown_table, text_table
from .advice_search import FEED, FREQUENCY, Advice, peak_position

BAR_WIDTH = 30


def _rock(advice: Advice) -> str:
    return advice.rock or "the scene's rock"


def best_point(advice: Advice) -> str:
    """'sandstone: best penetration rate 23.1 mm/s at impact frequency 66.2 Hz, feed force 81 kN (...)'."""
    y = metric(advice.metric)
    at = ", ".join(f"{parameter(p).name} {parameter(p).show_with_unit(v)}" for p, v in advice.best.items())
    if advice.power_w is not None:
        at += f" ({blow_energy_text(advice)})"
    failed = f", {advice.failed_runs} failed" if advice.failed_runs else ""
    failed += f", {advice.replayed} replayed from an earlier session" if advice.replayed else ""
    beyond = f", {advice.beyond_limit} points beyond the thrust limit not run" if advice.beyond_limit else ""
    stress = ""
    if advice.max_rod_stress_pa is not None:
        shown = metric("rod_stress_max_pa")
        stress = (f", largest rod stress {shown.show_with_unit(advice.best_rod_stress_pa)} (bound "
                  f"{shown.show_with_unit(advice.max_rod_stress_pa)}; {advice.beyond_stress} points above it)")
    return (f"{_rock(advice)}: best {y.name} {y.show_with_unit(advice.best_value)} at {at}, mean thrust "
            f"{advice.best_thrust_ratio:.0%} of F_th{stress} ({advice.formulation}, {advice.runs} runs{failed}{beyond}, "
            f"{advice.generations} generations{'' if advice.converged else ', not converged'}"
            f"{_beaten(advice, y)}, {advice.wall_time_s:.1f} s)")


def _beaten(advice: Advice, y: Any) -> str:
    """', a point of its curves beat the search's best 6.70 mm/s' where one did (advice_search module doc)."""
    if math.isnan(advice.search_best_value):
        return ""
    return f"; a point of its curves or map beat the search's own best {y.show_with_unit(advice.search_best_value)}"


def blow_energy_text(advice: Advice) -> str:
    """'blow energy 300 J at 15 kW': E_blow = P / f at the optimum's frequency (a fixed hammer power)."""
    energy = parameter("impact.piston.energy_j")
    return (f"{energy.name} {energy.show_with_unit(advice.power_w / advice.best[FREQUENCY])} at "
            f"{advice.power_w / 1e3:.4g} kW")


def curves_text(advice: Advice) -> str:
    """The metric along each parameter through the optimum, one table with bars per parameter ('-':
    not run, beyond the thrust limit, or failed)."""
    y = metric(advice.metric)
    top = float(np.nanmax([v for c in advice.slices.values() for v in c["metric"]] + [0.0])) or 1.0
    parts = []
    for path, curve in advice.slices.items():
        x = parameter(path)
        rows = [[x.show(value), "-" if math.isnan(value_y) else y.show(value_y),
                 ("" if math.isnan(value_y) else "#" * round(BAR_WIDTH * max(value_y, 0.0) / top))
                 + (" <- optimum" if value == advice.best[path] else "")]
                for value, value_y in zip(curve["values"], curve["metric"], strict=True)]
        band = " to ".join(x.show(b, 3) for b in curve["band_80"])
        parts.append(f"  along {x.name}, the others at the optimum (80 % band {band} {x.unit}):\n"
                     + "\n".join("    " + line for line in text_table([x.heading(), y.heading(), ""], rows).splitlines()))
    return "\n".join(parts)


def feed_lines(advice: Advice) -> list[str]:
    """Where the metric is highest along the feed force, frequency by frequency of the map."""
    f = parameter(FREQUENCY)
    kinds = advice.feed_map["response"]["frequencies_by_kind"]
    described = {"interior": "is highest inside the feed range (it rises, then falls with the feed)",
                 "highest feed": "is highest at the largest feed force",
                 "lowest feed": "is highest at the smallest feed force", "none": "is zero at every feed force"}
    return [f"{described[kind]} at {len(found)} of {len(advice.feed_map[FREQUENCY])} frequencies"
            + (f" ({', '.join(f.show(v, 3) for v in found)} {f.unit})" if found else "")
            for kind, found in kinds.items() if found]


def feed_text(advice: Advice) -> str:
    feed = parameter(FEED)
    bounds = " to ".join(feed.show(b, 3) for b in advice.bounds[FEED])
    return f"  {metric(advice.metric).name} against feed force ({bounds} {feed.unit}):\n" + \
        "\n".join(f"    {line}" for line in feed_lines(advice))


def advice_text(advice: Advice) -> str:
    return "\n".join([best_point(advice), curves_text(advice), feed_text(advice)])


def _band(advice: Advice, path: str) -> str:
    return "-".join(parameter(path).show(b, 3) for b in advice.slices[path]["band_80"])


def best_table(advices: list[Advice], markdown: bool = False) -> str:
    """One row per rock: the best point, the metric there, its 80 % bands, the runs and wall time."""
    paths = list(advices[0].best)
    y = metric(advices[0].metric)
    headings = ["rock", *(parameter(p).heading() for p in paths), y.heading(),
                *(f"80 % band, {parameter(p).heading()}" for p in paths), "mean thrust / F_th [%]", "runs",
                "wall time [s]"]
    power = advices[0].power_w is not None
    if power:  # the blow energy at the optimum, P / f
        headings.insert(1 + len(paths), parameter("impact.piston.energy_j").heading())
    rows = [[_rock(a), *(parameter(p).show(a.best[p]) for p in paths),
             *([parameter("impact.piston.energy_j").show(a.power_w / a.best[FREQUENCY])] if power else []),
             y.show(a.best_value),
             *(_band(a, p) for p in paths), f"{100 * a.best_thrust_ratio:.0f}", str(a.runs),
             f"{a.wall_time_s:.1f}"] for a in advices]
    return (markdown_table if markdown else text_table)(headings, rows)


def feed_at_optimum(advice: Advice) -> str:
    """What the metric does along the feed force at the optimum's frequency (the feed curve)."""
    curve, feed = advice.slices[FEED], parameter(FEED)
    kind = peak_position(curve["metric"])
    run = [v for v, m in zip(curve["values"], curve["metric"], strict=True) if not math.isnan(m)]
    if kind == "interior":
        return f"rises, then falls with the feed: an optimum feed force, {feed.show_with_unit(advice.best[FEED])}"
    if kind == "highest feed":
        end = "the upper bound" if run[-1] == curve["values"][-1] else "the thrust limit"
        return f"rises with the feed up to {end}, {feed.show_with_unit(run[-1])}: no optimum feed force inside the bounds"
    return {"lowest feed": "is highest at the smallest feed force", "none": "is zero at every feed force"}[kind]


def map_markdown(advice: Advice) -> str:
    """The feed x frequency map as a table (rows: feed forces, columns: frequencies), the best feed at
    each frequency in bold, '-' where not run (beyond the thrust limit) or failed."""
    f, feed, y = parameter(FREQUENCY), parameter(FEED), metric(advice.metric)
    grid = np.array(advice.feed_map["metric"], dtype=float)
    best = [int(np.nanargmax(column)) if np.any(column > 0) else -1 for column in grid.T]
    rows = [[feed.show(value, 3)] + ["-" if math.isnan(v) else f"**{y.show(v, 3)}**" if best[j] == i
                                               else y.show(v, 3) for j, v in enumerate(line)]
            for i, (value, line) in enumerate(zip(advice.feed_map[FEED], grid, strict=True))][::-1]
    headings = [f"{feed.name} [{feed.unit}] \\ {f.name} [{f.unit}]"] + [f.show(v, 3) for v in advice.feed_map[FREQUENCY]]
    return f"{y.name} [{y.unit}]:\n\n" + markdown_table(headings, rows)


LEFT_OUT = """The model has no term that makes a high feed cost anything. The feed acts on the axial chain
only: the torsion line of Eq. 4 is decoupled from it, so a higher feed brings no rise of the
rotation torque and no loss of the bit's indexing onto fresh rock. The Jenkins rock (Eq. 1, 2)
yields at a constant threshold F_th, whatever the depth of indentation and whatever lies under the
bit: no growth of the contact, no chipping, no regrinding of cuttings. The one limit it has is
static: where the mean thrust (feed + blow frequency x impulse per blow) reaches F_th, the rock
yields under the mean load and the rate is set by the rock damper alone (advise runs no point
beyond it). The falling branch of the experiments is usually attributed to exactly what is left
out (rotation torque and indexing, the bit-rock interface under a high load); modelling it would
take a torsion line coupled to the axial force (a torque on the bit that grows with the weight on
it) and a rock threshold that rises with the indentation. Where a map below has its maximum inside
the feed range at a fixed frequency, the best feed (bold) changes from frequency to frequency: the
feed moves the frequencies at which the drill responds to the blows, which is not the experiments'
mechanism."""


def advice_markdown(advices: list[Advice], command: str) -> str:
    """The Markdown report: the table of best points, the feed-force response and map per rock, what
    the model leaves out, the command that made it."""
    first = advices[0]
    y = metric(first.metric)
    feed = "\n\n".join(
        f"### {_rock(a)}\n\nAt the optimum's frequency, {parameter(FREQUENCY).show_with_unit(a.best[FREQUENCY])}, "
        f"the {y.name} {feed_at_optimum(a)}. Over the map, the {y.name}:\n\n"
        + "\n".join(f"- {line}" for line in feed_lines(a)) + "\n\n" + map_markdown(a) for a in advices)
    return f"""# Best operating points

Generated by `{command}`; do not edit by hand (run the command again after a change of the scene).
The best {y.name} within the bounds, found by differential evolution on the {first.formulation} formulation
({first.end_time_s:g} s runs; studies/advice/advice_search.py). The 80 % bands are the intervals, one parameter at a
time with the others at the optimum, where the {y.name} stays at or above 80 % of its best value;
the mean thrust is the feed plus the blow frequency times the impulse per blow, as a share of the
rock's threshold F_th. Scene: {first.scene_description}.{_power_sentence(first)}

{best_table(advices, markdown=True)}

## Feed force: does the model have an optimum?

In experiments percussive drilling has an optimum feed force: at a given blow the rate rises, then
falls, as the feed grows. Below, for each rock, the {y.name} along the feed at the optimum's
frequency, where it is highest along the feed at each frequency of a {len(first.feed_map[FREQUENCY])} x
{len(first.feed_map[FEED])} feed x frequency map (other parameters at the optimum), and the map.

{LEFT_OUT}

{feed}
"""


def _power_sentence(advice: Advice) -> str:
    if advice.power_w is None:
        return ""
    return (f" At a fixed hammer power of {advice.power_w / 1e3:.4g} kW: at every point the piston's blow energy is "
            "the power over the frequency, E_blow = P / f.")


def advice_record(advices: list[Advice], command: str) -> dict[str, Any]:
    """advice.json: the command and every rock's result in SI units."""
    return {"command": command, "results": [dataclasses.asdict(a) for a in advices]}
