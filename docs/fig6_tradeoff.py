"""The trade-off between the paper's Fig. 6 and its other headlines in a calibration run (docs/fig6.md).

    python docs/fig6_tradeoff.py RUN_DIR [RUN_DIR ...]

RUN_DIR: the --out of ``rpdrill calibrate studies/paper/calibration.yaml`` (its evaluations.jsonl, each
target's optimum as studies.scan.curve_optima.Optimum.record: a run of rpdrill before that record's
layout 2 is refused by ``rpdrill calibrate`` and not read here). For
every evaluation: "rest", the largest |relative miss| of 3.1 a), 3.1 b) and Fig. 5 (1 when the 3.1 b)
optima do not rise with the impulse); "Fig. 6", the larger |miss| at the two stiffnesses the paper
gives (80 Hz at 8.93e7, 90 Hz at 8.4e8 N/m; 1 unless all four Fig. 6 scans have a penetration
optimum inside the scan). Prints the non-dominated evaluations of (rest, Fig. 6), and how the softest
rock's penetration optimum follows its collar-velocity optimum (Fig. 5).
"""

from __future__ import annotations

import json
import statistics
import sys
from pathlib import Path

from rpdrill.models.evaluation.workprecision import non_dominated

REST = ("3.1 a)", "3.1 b) 160 kN", "3.1 b) 220 kN", "3.1 b) 280 kN", "3.2 k = 8.93e7", "3.2 k = 8.4e8 (conglomerate)")
RISING = ("3.1 b) 160 kN", "3.1 b) 220 kN", "3.1 b) 280 kN")
FIG6 = ("3.2 Fig. 6 k = 8.93e7", "3.2 Fig. 6 k = 2.1e8", "3.2 Fig. 6 k = 5.1e8", "3.2 Fig. 6 k = 8.4e8")
ENDS = (FIG6[0], FIG6[3])


def misses(record: dict, labels: list[str]) -> tuple[float, float]:
    """(rest, Fig. 6) of one evaluation (module doc)."""
    target = dict(zip(labels, record["targets"], strict=True))
    rest = max(abs(target[label]["miss"]) for label in REST)
    rising = [target[label]["optimum"] for label in RISING]
    if None in rising or not rising[0] < rising[1] < rising[2]:
        rest = max(rest, 1.0)
    inside = all(target[label]["optimum"] is not None and not target[label]["peak_at_scan_end"] for label in FIG6)
    fig6 = max(abs(target[label]["miss"]) for label in ENDS) if inside else 1.0
    return rest, fig6


def report(run: Path) -> None:
    labels = [t["label"] for t in json.loads((run / "calibration.json").read_text())["calibration"]["targets"]]
    records = [json.loads(line) for line in (run / "evaluations.jsonl").read_text().splitlines() if line.strip()]
    points = [misses(r, labels) for r in records]
    front = sorted({points[i]: i for i in reversed(non_dominated(points))}.values(), key=lambda i: points[i])
    print(f"{run}: {len(records)} evaluations; the front of (rest, Fig. 6), largest relative misses:")
    print("| evaluation | rest | Fig. 6 | Fig. 6 optima (Hz), k rising | Fig. 6 peak values (mm/s; mm for the displacement reading) |")
    print("|---|---|---|---|---|")
    for i in front:
        target = dict(zip(labels, records[i]["targets"], strict=True))
        hz = ", ".join("none" if target[label]["optimum"] is None else f"{target[label]['optimum']:.1f}"
                       for label in FIG6)
        rates = ", ".join(f"{1e3 * (target[label]['optimum_value'] or 0.0):.3g}" for label in FIG6)
        print(f"| {i} | {points[i][0]:.3f} | {points[i][1]:.3f} | {hz} | {rates} |")
    ratios = []
    for record in records:
        target = dict(zip(labels, record["targets"], strict=True))
        soft, collar = target[FIG6[0]], target["3.2 k = 8.93e7"]
        if soft["optimum"] and collar["optimum"] and not soft["peak_at_scan_end"]:
            ratios.append(soft["optimum"] / collar["optimum"])
    if ratios:
        near = sum(abs(r - 1.0) <= 0.15 for r in ratios) / len(ratios)
        print(f"softest rock, penetration optimum / collar-velocity optimum over {len(ratios)} evaluations with a "
              f"penetration optimum inside the scan: median {statistics.median(ratios):.3f}, within 15 % of 1: "
              f"{near:.0%}")
    both = sum(all(abs(dict(zip(labels, r["targets"], strict=True))[label]["miss"]) <= 0.15 for label in REST)
               for r in records)
    print(f"evaluations with all six other headlines within 15 %: {both}")


if __name__ == "__main__":
    for folder in sys.argv[1:]:
        report(Path(folder))
