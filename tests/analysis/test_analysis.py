"""Alignment of two runs as in the paper's Figure 7 (time and position shift)."""
import numpy as np
import pytest

from ipfric_core.analysis.recorded_run import alignment_shift, run_name


def test_alignment_recovers_time_and_position_shift():
    t = np.arange(0, 20, 1e-3)
    ref = 7e-3 * np.sign(np.sin(2 * np.pi * t / 2.7)) + 2e-3 * np.sin(2 * np.pi * t / 0.9)
    # the other run: the same motion 0.7 s later, from a cart position 3 mm off
    t2 = np.arange(0, 18, 1e-3)
    other = np.interp(t2 - 0.7, t, ref) - 3e-3
    dt, dx = alignment_shift(t, ref, t2, other)
    assert dt == pytest.approx(-0.7, abs=2e-3)
    assert dx == pytest.approx(3e-3, abs=2e-4)


def test_run_names_skip_generic_parts(tmp_path):
    assert run_name(tmp_path / 'fig7' / 'bag' / 'bag_0.mcap') == 'fig7'
    assert run_name(tmp_path / 'sweep' / 'tau0.0100_theta1.0000' / 'run') == 'tau0.0100_theta1.0000'
    assert run_name(tmp_path / 'x.mcap') == 'x'
