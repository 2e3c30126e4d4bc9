"""The independent code of ``tests/independent`` (its own integrator and formulas, nothing of
ipfric_core) for the bench: imported from ``tests/`` as the package ``independent``, the name the
tests import it by, so that numba's cache of its kernels (keyed by the module's name) serves both."""
import sys
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1] / 'tests'
if str(TESTS) not in sys.path:
    sys.path.insert(0, str(TESTS))

from independent import campaign, rigsim  # noqa: E402

__all__ = ['campaign', 'rigsim']
