"""The command line each example of the gallery runs with at the build (sphinx-gallery's ``reset_argv``):
its defaults, its figure written into the build folder rather than into examples/."""

from __future__ import annotations

from pathlib import Path

FIGURES = Path(__file__).resolve().parent / "_build" / "gallery_figures"


def example_arguments(gallery_conf: dict, script_vars: dict) -> list[str]:
    """``--figure docs/_build/gallery_figures/<example>.png``."""
    FIGURES.mkdir(parents=True, exist_ok=True)
    return ["--figure", str(FIGURES / f"{Path(script_vars['src_file']).stem}.png")]
