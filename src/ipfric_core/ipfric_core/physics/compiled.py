"""How the physics is compiled: numba's ``njit`` with an on-disk cache per source version.

numba checks a cached function against its own file only; a function that calls one of
another module (the closed loop calls the integrator, which calls the friction law) would
keep a stale copy of the callee after an edit. So every module with compiled code shares
one cache directory named by a hash of all of them: any edit starts a fresh cache.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numba

_HERE = Path(__file__).resolve().parent
_SOURCES = sorted(p for p in _HERE.parent.rglob('*.py') if '@compiled' in p.read_text())
_KEY = hashlib.sha256(b''.join(p.read_bytes() for p in _SOURCES)).hexdigest()[:16]
numba.config.CACHE_DIR = str(  # type: ignore[attr-defined]  # set at numba's import
    _HERE / '__pycache__' / f'numba-{_KEY}')


def compiled(fn):
    """``fn`` compiled to machine code on first use (or loaded from the cache)."""
    return numba.njit(cache=True)(fn)
