"""Run a study from Python into a pandas table and plot it.

Shows: ``rpdrill.load_study`` reads a study file (here the paper's frequency scan, run with the exact
formulation), ``rpdrill.run_study`` runs its points on all cores and returns a DataFrame (one row a
point, numbers typed); the penetration rate against impact frequency is plotted with matplotlib and
its best grid point printed.

    python examples/study_to_pandas.py [--out frequency_scan.png] [--workers N]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import rpdrill

STUDY = Path(__file__).resolve().parents[1] / "studies" / "paper" / "frequency_scan.yaml"


def main() -> float:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("frequency_scan.png"))
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()
    study = rpdrill.load_study(STUDY, formulation="exact")
    table = rpdrill.run_study(study, workers=args.workers)
    table["penetration_rate_mm_per_s"] = 1e3 * table["penetration_rate_m_per_s"]
    best = table.loc[table["penetration_rate_mm_per_s"].idxmax()]
    print(table[["impact.frequency_hz", "penetration_rate_mm_per_s", "bit_velocity_peak_m_per_s"]].to_string(index=False))
    print(f"best grid point: {best['impact.frequency_hz']:.0f} Hz, {best['penetration_rate_mm_per_s']:.2f} mm/s")
    figure, axes = plt.subplots(figsize=(6, 3.5))
    axes.plot(table["impact.frequency_hz"], table["penetration_rate_mm_per_s"], marker="o")
    axes.set_xlabel("impact frequency f (Hz)")
    axes.set_ylabel("penetration rate (mm/s)")
    axes.set_title(f"{study.spec.name}: penetration rate against impact frequency (exact)")
    figure.tight_layout()
    figure.savefig(args.out)
    print(f"wrote {args.out}")
    return float(best["impact.frequency_hz"])


if __name__ == "__main__":
    main()
