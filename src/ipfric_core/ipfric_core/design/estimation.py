"""Friction coefficients from the cart-alone experiments of the paper's appendix.

Steady sliding at constant voltage (eq. 36): alpha V - beta v = mu_c M g + eps v.
Breakaway on a voltage ramp (eq. 37): mu_s M g = alpha V_s.
"""
from __future__ import annotations

import csv
import itertools
from pathlib import Path

import numpy as np

from ..physics.params import ConfigError, PlantParams

__all__ = ['load_table5', 'coulomb_viscous', 'load_table6', 'static_coefficient']


def _rows(path: str | Path) -> list[dict]:
    path = Path(path)
    lines = [ln for ln in path.read_text().splitlines() if ln.strip() and not ln.startswith('#')]
    return list(csv.DictReader(lines))


def load_table5(path: str | Path, outlier_fraction: float = 0.1):
    """Runs of the constant-voltage table (Table 5).

    Returns (volts, velocities) of the individual runs, the per-voltage (volts,
    averages) printed in the table, and the runs set aside because they differ from
    their printed row average by more than ``outlier_fraction`` (each as
    (voltage, value, printed average)); those are reported, not silently dropped.
    """
    volts, vels, avg_v, avg, suspect = [], [], [], [], []
    for row in _rows(path):
        try:
            v = float(row['voltage_V'])
            runs = [float(row[k]) for k in row if k.startswith('run') and row[k] not in ('', None)]
            a = float(row['average_mps'])
        except (KeyError, ValueError) as exc:
            raise ConfigError(f'{path}: bad row {row}: {exc}') from exc
        for r in runs:
            if abs(r - a) > outlier_fraction * a:
                suspect.append((v, r, a))
            else:
                volts.append(v)
                vels.append(r)
        avg_v.append(v)
        avg.append(a)
    return np.array(volts), np.array(vels), np.array(avg_v), np.array(avg), suspect


def coulomb_viscous(plant: PlantParams, volts, vels) -> dict:
    """Least-squares mu_c, eps [N s/m] from steady (V, v) pairs, eq. (36), F_N = M g.

    Also returns the standard errors and the paper's procedure (mean of the pairwise
    two-point solutions) on the same points.
    """
    V, v = np.asarray(volts, float), np.asarray(vels, float)
    y = plant.alpha * V - plant.beta * v
    X = np.column_stack([np.full_like(v, plant.M * plant.g), v])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ coef
    dof = max(1, len(v) - 2)
    cov = np.linalg.inv(X.T @ X) * (resid @ resid) / dof
    pairs = []
    for i, j in itertools.combinations(range(len(v)), 2):
        if V[i] != V[j]:
            eps = (plant.alpha * (V[i] - V[j]) - plant.beta * (v[i] - v[j])) / (v[i] - v[j])
            pairs.append(((plant.alpha * V[i] - (plant.beta + eps) * v[i]) / (plant.M * plant.g), eps))
    table = np.array(pairs)
    return {
        'mu_c': float(coef[0]), 'eps': float(coef[1]),
        'mu_c_std': float(np.sqrt(cov[0, 0])), 'eps_std': float(np.sqrt(cov[1, 1])),
        'residual_rms_N': float(np.sqrt(np.mean(resid ** 2))),
        'pairwise_mean': {'mu_c': float(table[:, 0].mean()), 'eps': float(table[:, 1].mean())},
        'pairwise_spread': {'mu_c': float(table[:, 0].std()), 'eps': float(table[:, 1].std())},
        'n_points': int(len(v)),
    }


def load_table6(path: str | Path) -> np.ndarray:
    """Breakaway voltages [V] of the ramp runs."""
    try:
        return np.array([float(r['voltage_V']) for r in _rows(path)])
    except (KeyError, ValueError) as exc:
        raise ConfigError(f'{path}: expected a column voltage_V of numbers ({exc})') from exc


def static_coefficient(plant: PlantParams, breakaway_volts) -> dict:
    """mu_s = alpha mean(V_s) / (M g), eq. (37), with its standard error."""
    V = np.asarray(breakaway_volts, float)
    k = plant.alpha / (plant.M * plant.g)
    return {'mu_s': float(k * V.mean()), 'mu_s_std': float(k * V.std(ddof=1) / np.sqrt(len(V))),
            'mean_voltage': float(V.mean()), 'n_runs': int(len(V))}
