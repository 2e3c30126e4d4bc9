"""How the physics is compiled: numba's ``njit`` with an on-disk cache per source version.

numba checks a cached function against its own file only; a function that calls one of
another module (the closed loop calls the integrator, which calls the friction law) would
keep a stale copy of the callee after an edit. So every module with compiled code shares
one cache directory named by a hash of all of them: any edit starts a fresh cache.

The caches live outside the source tree, in :func:`cache_root` (``$IPFRIC_CACHE_DIR``, by
default ``${XDG_CACHE_HOME:-~/.cache}/ipfric``), as ``numba-<hash>``. Each import marks its
own cache as used; the caches of other source versions are removed once unused for
:data:`STALE_AFTER_S` (other checkouts on the machine share the directory and keep theirs).
"""
from __future__ import annotations

import hashlib
import os
import shutil
import time
from pathlib import Path

import numba

__all__ = ['compiled']

#: a cache of another source version that no import has used for this long is removed [s]
STALE_AFTER_S = 86400.0


def cache_root() -> Path:
    """Directory of the numba caches: ``$IPFRIC_CACHE_DIR``, else ``${XDG_CACHE_HOME:-~/.cache}/ipfric``."""
    if os.environ.get('IPFRIC_CACHE_DIR'):
        return Path(os.environ['IPFRIC_CACHE_DIR'])
    return Path(os.environ.get('XDG_CACHE_HOME') or Path.home() / '.cache') / 'ipfric'


def source_key() -> str:
    """Hash of every ipfric_core module with compiled code (16 hex digits)."""
    package = Path(__file__).resolve().parent.parent
    sources = sorted(p for p in package.rglob('*.py') if '@compiled' in p.read_text())
    return hashlib.sha256(b''.join(p.read_bytes() for p in sources)).hexdigest()[:16]


def prune(root: Path, keep: Path, now: float, stale_after: float = STALE_AFTER_S) -> list[Path]:
    """Remove the ``numba-*`` directories of ``root`` except ``keep`` not used for ``stale_after``
    [s] before ``now`` [s since the epoch]; returns the removed ones."""
    removed = []
    for d in sorted(root.glob('numba-*')):
        if d != keep and d.is_dir() and now - d.stat().st_mtime > stale_after:
            shutil.rmtree(d, ignore_errors=True)
            removed.append(d)
    return removed


def use_cache(root: Path) -> Path:
    """Point numba at ``root``/numba-<source key>, mark it as used and prune stale siblings."""
    path = root / f'numba-{source_key()}'
    path.mkdir(parents=True, exist_ok=True)
    os.utime(path)
    prune(root, path, time.time())
    numba.config.CACHE_DIR = str(path)  # type: ignore[attr-defined]  # numba sets its config at import
    return path


#: the cache directory of this source version
CACHE_DIR = use_cache(cache_root())


def compiled(fn=None, *, parallel: bool = False):
    """``fn`` compiled to machine code on first use (or loaded from the cache); as
    ``@compiled(parallel=True)`` its ``numba.prange`` loops run on every core."""
    if fn is None:
        return lambda f: numba.njit(cache=True, parallel=parallel)(f)
    return numba.njit(cache=True)(fn)
