"""What a test reads off a picture a command wrote."""

from pathlib import Path

import numpy as np
from PIL import Image


def inked_at_the_edges(movie: Path) -> int:
    """The pixels darker than light grey in the first frame's outer 3 rows and columns: 0 when the frame is
    laid out with its labels inside it (the model's animation was never laid out: its x label was cut in half
    at the bottom edge, 214 such pixels)."""
    with Image.open(movie) as frames:
        frames.seek(0)
        rgb = np.asarray(frames.convert("RGB"))
    edges = np.concatenate([rgb[:3], rgb[-3:], rgb[:, :3].transpose(1, 0, 2), rgb[:, -3:].transpose(1, 0, 2)], axis=1)
    return int((edges.min(axis=2) < 200).sum())
