"""Incremental-encoder measurement: positions rounded to whole counts (paper section 6).

The paper rig's resolutions are ``constants.ANGLE_RESOLUTION_RAD`` (0.08789 deg, 4096
counts/rev) and ``constants.CART_RESOLUTION_M`` (0.00454 cm).
"""
from __future__ import annotations

import numpy as np

from .compiled import compiled

__all__ = ['quantize']


@compiled
def quantize(value: float, resolution: float) -> float:
    """``value`` rounded to the nearest multiple of ``resolution`` (0 disables; halves to even)."""
    if resolution <= 0.0:
        return value
    return resolution * np.round(value / resolution)
