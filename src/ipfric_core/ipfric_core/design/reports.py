"""The paper's design and stability numbers, computed and set beside the printed ones.

Each function returns a plain dict (JSON-ready); ``./ipfric design`` and
``./ipfric stability`` print them.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from . import paper
from .critical_delay import gain_critical_delay
from .estimation import coulomb_viscous, load_table5, load_table6, static_coefficient
from .linearize import jacobian
from .lqr import controllability_matrix, design
from .paperconfig import PaperConfig
from .stability import delta_thresholds

__all__ = ['design_report', 'stability_report']


def _cmp(ours, printed) -> dict:
    ours = np.asarray(ours, float)
    printed = np.asarray(printed, float)
    with np.errstate(divide='ignore', invalid='ignore'):
        rel = np.where(printed != 0, np.abs(ours - printed) / np.abs(printed), np.abs(ours - printed))
    return {'ipfric': ours.round(6).tolist(), 'paper': printed.tolist(),
            'max_rel_diff': float(rel.max())}


def _eig_list(eigs) -> list:
    eigs = sorted(np.asarray(eigs, complex), key=lambda e: (-e.real, e.imag))
    return [[round(e.real, 6), round(e.imag, 6)] for e in eigs]


def design_report(cfg: PaperConfig, data_dir: str | Path | None = None) -> dict:
    """Gains (15), (23), (25), eigenvalues of section 4.2 and the appendix estimates."""
    out: dict = {'gains': {}, 'eigenvalues': {}, 'controllability_rank': {}}
    printed = {'viscous': paper.GAIN_15_VISCOUS, 'exponential': paper.GAIN_23_EXPONENTIAL,
               'dynamic': paper.GAIN_25_DYNAMIC}
    designs = {}
    for name, gain in printed.items():
        d = design(cfg.plant, cfg.friction[name], cfg.Q, cfg.R)
        designs[name] = d
        entry = _cmp(d.gain, gain)
        entry['equation'] = {'viscous': '(15)', 'exponential': '(23)', 'dynamic': '(25)'}[name]
        if d.reduced_gain is not None:
            entry['full_gain_with_z'] = d.full_gain.round(6).tolist()
        out['gains'][name] = entry
        A, B = jacobian(cfg.plant, cfg.friction[name])
        out['controllability_rank'][name] = {
            'rank': int(np.linalg.matrix_rank(controllability_matrix(A, B), tol=1e-9 * np.abs(A).max())),
            'n_states': int(A.shape[0])}
    A, B = jacobian(cfg.plant, cfg.friction['dynamic'])
    for label, gain, ref in [('dynamic_gain_15', paper.GAIN_15_VISCOUS, paper.EIG_DYNAMIC_GAIN_15),
                             ('dynamic_gain_25', paper.GAIN_25_DYNAMIC, paper.EIG_DYNAMIC_GAIN_25)]:
        K = np.zeros(5)
        K[:4] = gain[:4]
        eig = np.linalg.eigvals(A + B @ K[None, :])
        out['eigenvalues'][label] = {'ipfric': _eig_list(eig), 'paper': _eig_list(ref)}
    if data_dir is not None:
        out['friction_estimates'] = friction_estimates(cfg, data_dir)
    return out


def friction_estimates(cfg: PaperConfig, data_dir: str | Path) -> dict:
    """mu_c, eps (Table 5) and mu_s (Table 6) of the cart alone, F_N = M g."""
    data_dir = Path(data_dir)
    V, v, Va, va, suspect = load_table5(data_dir / 'table5_constant_voltage.csv')
    on_avg = coulomb_viscous(cfg.plant, Va, va)
    on_runs = coulomb_viscous(cfg.plant, V, v)
    s = static_coefficient(cfg.plant, load_table6(data_dir / 'table6_breakaway_voltage.csv'))
    return {
        'mu_s': {'ipfric': round(s['mu_s'], 6), 'std': round(s['mu_s_std'], 6), 'paper': paper.MU_S,
                 'mean_breakaway_V': round(s['mean_voltage'], 6), 'paper_mean_V': paper.BREAKAWAY_MEAN_V},
        'table5_row_averages': on_avg,
        'table5_individual_runs': on_runs,
        'table5_runs_set_aside': [{'voltage_V': a, 'value_mps': b, 'row_average_mps': c}
                                  for a, b, c in suspect],
        'paper': {'mu_c': paper.MU_C, 'eps': paper.EPS},
    }


def stability_report(cfg: PaperConfig) -> dict:
    """Routh-Hurwitz thresholds in delta (section 3.1) and the critical delays (section 5)."""
    expo = cfg.friction['exponential']
    th = delta_thresholds(cfg.plant, expo, paper.GAIN_15_VISCOUS)
    out = {'routh_hurwitz_gain_15_exponential': {
        'unstable_above_delta': {'ipfric': round(th['unstable_above'], 4), 'paper': paper.DELTA_UNSTABLE_ABOVE},
        'complex_pair_until_delta': {'ipfric': round(th['complex_until'], 4), 'paper': paper.DELTA_COMPLEX_UNTIL},
        'rhp_roots_beyond': th['rhp_roots']}}
    tau = {}
    for name, gain, ref in [('exponential', paper.GAIN_23_EXPONENTIAL, paper.TAU_C_EXPONENTIAL),
                            ('dynamic', paper.GAIN_25_DYNAMIC, paper.TAU_C_DYNAMIC)]:
        A, B = jacobian(cfg.plant, cfg.friction[name])
        r = gain_critical_delay(A, B, gain)
        tau[name] = {'ipfric': round(r['tau_c'], 6), 'paper': ref,
                     'crossing_frequency_hz': round(r['frequency_hz'], 4)}
        if name == 'dynamic':
            full = design(cfg.plant, cfg.friction[name], cfg.Q, cfg.R).full_gain
            r2 = gain_critical_delay(A, B, full)
            tau[name]['with_full_gain_incl_z'] = round(r2['tau_c'], 6)
    tau['exponential']['delta'] = expo.delta
    out['critical_delay_s'] = tau
    return out
