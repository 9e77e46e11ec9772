"""Variable-density blue noise from an image, drawn with matplotlib (the README's picture).

    python examples/image_points.py [IMAGE] [--out points.png]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import rwt_noise as rwt  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("image", nargs="?", default=ROOT / "assets/images/sphere.png")
    parser.add_argument("--out", default="points.png")
    args = parser.parse_args()
    image = plt.imread(args.image)
    grey = image if image.ndim == 2 else image[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    h, w = grey.shape
    rect = (0.0, 0.0, float(w), float(h))
    # Dark is dense: 9 000 points in all, wherever the image asks for them.
    s = rwt.sample(rect, 1.0 - grey, n=9_000, seed=1)

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 5))
    left.imshow(grey, cmap="gray", vmin=0, vmax=1, extent=(0, w, 0, h))
    left.set_title("density: the image, dark is dense")
    right.scatter(s.points[:, 0], s.points[:, 1], s=2.5, c="black", linewidths=0)
    right.set_title(f"rwt.sample(rect, 1 - grey, n={len(s)})")
    for ax in (left, right):
        ax.set_xlim(0, w)
        ax.set_ylim(0, h)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"{len(s)} points; wrote {args.out}")


if __name__ == "__main__":
    main()
