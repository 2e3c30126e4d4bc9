"""A model run free over a whole held-out record: the nonlinear system-identification
benchmarks' test protocol.

The model is simulated from the record's command alone, from the state its first
``init`` readings give (the benchmarks' ``state_initialization_window_length``: 20 samples
for EMPS), and compared with every reading after them; no reading after the first ``init``
enters the simulation. The error is the RMS of simulated minus measured position over those
readings, in mm (the EMPS benchmark's figure) and in encoder counts.
"""
from __future__ import annotations

import numpy as np

from ..analysis.records import Record, smooth_rate
from . import shooting
from .model import Model

__all__ = ['INIT_SAMPLES', 'free_run']

#: readings that initialise the state (the EMPS benchmark's state_initialization_window_length)
INIT_SAMPLES = 20


def free_run(model: Model, rec: Record, init: int = INIT_SAMPLES) -> dict:
    """``model`` run free over ``rec`` from the state of its first ``init`` readings (position: the last
    of them; speed: the slope of a quadratic through them, 0 where the encoder stood still): the RMS
    error of the position over the readings after them [mm and counts], with the simulated and measured
    positions (arrays, for a figure)."""
    if not 3 <= init < len(rec.t) - 1:
        raise ValueError(f'init: {init} samples; allowed 3 .. {len(rec.t) - 2} for {rec.name}')
    head = rec.part(0, init, 'initialisation')
    k = init - 1
    held = float(shooting.still(head.t, head.x)[k] or np.ptp(head.x) == 0.0)
    v = 0.0 if held else float(np.polyfit(head.t - head.t[k], head.x, 2)[1])
    th = rec.theta if rec.theta is not None else np.zeros(len(rec.t))
    w = float(np.polyfit(head.t - head.t[k], th[:init], 2)[1]) if rec.theta is not None else 0.0
    speed = np.zeros(len(rec.t))
    speed[:init] = smooth_rate(head.t, head.x, head.valid_mask, shooting.FILTER_HZ)
    win = shooting.Windows(np.array([k]), np.array([len(rec.t)]), np.array([[rec.x[k], th[k], v, w, 0.0]]),
                           np.array([held]), np.zeros((0, 2)), np.column_stack([speed, np.zeros(len(rec.t))]))
    pred = shooting.predict(model.vectors(), rec, win)
    c = pred.compared
    err = pred.x[c] - rec.x[c]
    err = np.where(np.isfinite(err), err, np.nan)
    rms = float(np.sqrt(np.nanmean(err ** 2))) if np.isfinite(err).any() else float('nan')
    return {'record': rec.name, 'init_samples': init, 'samples': int(c.sum()),
            'diverged_samples': int(np.sum(~np.isfinite(err))), 'rmse_mm': 1e3 * rms,
            'rmse_counts': rms / rec.x_resolution, 'travel_mm': 1e3 * float(np.ptp(rec.x)),
            't': rec.t, 'simulated': pred.x, 'measured': rec.x}
