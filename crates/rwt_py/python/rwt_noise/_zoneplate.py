"""`rwt.zoneplate`: the paper's anti-aliasing test (Kopf et al. 2006, figure 9)."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Dict, Optional, Tuple, Union

import numpy as np

from . import _rwt
from ._sample import Count, MAX_SEED, _count


@dataclass(frozen=True)
class ZonePlateResult:
    """The zone plate rendered by each pattern. ``errors[name]`` is ``(psnr, low, high)``
    in dB against the supersampled reference: the whole error, its low band (aliasing) and
    its high band (noise); higher is better. ``images[name]`` is the ``(size, size)`` image
    (values -1..1, row 0 at the bottom), ``images["reference"]`` the reference."""

    errors: Dict[str, Tuple[float, float, float]]
    images: Dict[str, np.ndarray]
    _claim: Tuple[bool, bool] = field(repr=False)

    def claim(self) -> Tuple[bool, bool]:
        """The paper's claim, checked (as ``rwt zoneplate`` checks it): aliasing removed as
        jittering removes it (rwt's low band above the grid's and within 10 % of
        jittering's error), at a lower noise level (rwt's high band above jittering's)."""
        return self._claim


def zoneplate(*, size: Count = 512, seed: Count = 0,
              out: Optional[Union[str, "os.PathLike[str]"]] = None) -> ZonePlateResult:
    """Renders ``sin(x^2 + y^2)`` at ``size x size`` pixels with one sample per pixel and a
    Gaussian reconstruction filter, for rwt, a regular grid, jittering, white noise, dart
    throwing and Owen-scrambled Sobol, against the same filter over 16 stratified samples a
    pixel (``rwt zoneplate`` runs the same code). The plate's frequency reaches twice the
    pixels' Nyquist frequency at the middle of its edges. With ``out``, the images are
    drawn side by side into that PNG (needs matplotlib).

    >>> import rwt_noise as rwt
    >>> result = rwt.zoneplate(size=64)
    >>> sorted(result.errors) == sorted(["rwt", "grid", "jitter", "white", "dart", "sobol"])
    True
    """
    names, errors, images, claim = _rwt.zoneplate(size=_count(size, "size", MAX_SEED),
                                                  seed=_count(seed, "seed", MAX_SEED))
    result = ZonePlateResult(
        errors={n: (float(e[0]), float(e[1]), float(e[2])) for n, e in zip(names, errors)},
        images={n: images[k] for k, n in enumerate(["reference", *names])},
        _claim=claim,
    )
    if out is not None:
        _draw(result, out)
    return result


def _draw(result: ZonePlateResult, out: Union[str, "os.PathLike[str]"]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(result.images)
    fig, axes = plt.subplots(1, len(names), figsize=(2.2 * len(names), 2.6))
    for ax, name in zip(axes, names):
        ax.imshow(result.images[name], cmap="gray", vmin=-1, vmax=1, origin="lower")
        ax.set_axis_off()
        title = name if name == "reference" else \
            f"{name}\n{result.errors[name][1]:.1f} / {result.errors[name][2]:.1f} dB"
        ax.set_title(title, fontsize=8)
    fig.tight_layout()
    fig.savefig(os.fspath(out), dpi=150)
    plt.close(fig)
