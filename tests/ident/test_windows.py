"""The windows of the simulation error (ident/shooting.make_windows): every valid reading of the record is
judged, the tail of a stretch too short for a window of its own with the last window."""
import numpy as np

from ipfric_core.analysis.records import Record
from ipfric_core.ident.shooting import CART_WINDOW_S, cart_windows


def test_a_tail_too_short_for_a_window_is_judged_with_the_last_one():
    """A cart moving without rest for 3.2 s at 1 kHz: 1 s windows from 0.1 s leave a tail of 0.1 s, shorter
    than 0.3 of a window, which joins the last window (seed 2027's case 175: the one clipped move of its
    estimation part lay in such a tail, and its saturation was fitted on windows without clipping)."""
    t = np.arange(3200) * 1e-3
    x = np.round(0.05 * np.sin(2 * np.pi * 0.7 * t) / 1e-5) * 1e-5
    win = cart_windows(Record('moving', t, x, np.sin(t), 1.0))
    assert win.stop[-1] == len(t)
    assert t[win.stop[-1] - 1] - t[win.start[-1]] < 1.3 * CART_WINDOW_S
    assert np.all(win.start[1:] == win.stop[:-1] - 1)       # each window starts where the one before ends
