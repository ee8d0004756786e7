"""
A study from Python into a pandas table, and its plot
=====================================================

``rpdrill.load_study`` reads a study file (here the shipped paper's frequency scan, ``paper/frequency_scan``,
run with the exact formulation), ``rpdrill.run_study`` runs its points on all cores and returns a DataFrame
(one row a point, numbers typed); the penetration rate against the impact frequency is plotted with
matplotlib and its best grid point printed. ::

    python examples/study_to_pandas.py [--figure frequency_scan.png] [--workers N]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib.pyplot as plt

import rpdrill


def main() -> float:
    parser = argparse.ArgumentParser(description="A study from Python into a pandas table, and its plot")
    parser.add_argument("--figure", type=Path, default=Path("frequency_scan.png"))
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()
    study = rpdrill.load_study("paper/frequency_scan", formulation="exact")  # a shipped study
    table = rpdrill.run_study(study, workers=args.workers)
    table["penetration_rate_mm_per_s"] = 1e3 * table["penetration_rate_m_per_s"]
    best = table.loc[table["penetration_rate_mm_per_s"].idxmax()]
    print(table[["impact.frequency_hz", "penetration_rate_mm_per_s", "bit_velocity_peak_m_per_s"]].to_string(index=False))
    print(f"best grid point: {best['impact.frequency_hz']:.0f} Hz, {best['penetration_rate_mm_per_s']:.2f} mm/s")
    figure, axes = plt.subplots(figsize=(7, 3.5), layout="constrained")
    axes.plot(table["impact.frequency_hz"], table["penetration_rate_mm_per_s"], marker="o")
    axes.set_xlabel("impact frequency f (Hz)")
    axes.set_ylabel("penetration rate (mm/s)")
    axes.set_title(f"{study.spec.name}: penetration rate against impact frequency (exact)")
    figure.savefig(args.figure)
    print(f"wrote {args.figure}")
    return float(best["impact.frequency_hz"])


if __name__ == "__main__":
    main()
