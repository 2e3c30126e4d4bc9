"""What every command prints the same way: JSON results, progress lines, rows set beside the paper's."""
from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

from ..physics.params import ConfigError

__all__ = ['output_dir', 'print_json', 'progress_counter', 'progress_lines', 'paper_row', 'eig_text']


def output_dir(path: str | Path | None, option: str = '--out') -> Path | None:
    """``path`` of a command's output directory, checked before any work: a new or existing directory,
    not an existing file (nor anything else that is not a directory). None stays None."""
    if path is None:
        return None
    p = Path(path)
    if p.exists() and not p.is_dir():
        kind = 'a file' if p.is_file() else 'not a directory'
        raise ConfigError(f'{option}: {str(path)} is {kind}; allowed: a directory (new or existing)')
    for parent in p.parents:
        if parent.exists() and not parent.is_dir():
            raise ConfigError(f'{option}: {str(path)}: {parent} is a file; allowed: a directory (new or existing)')
    return p


def print_json(obj) -> None:
    """``obj`` as indented JSON on stdout (numpy numbers as floats)."""
    json.dump(obj, sys.stdout, indent=2, default=float)
    sys.stdout.write('\n')


def progress_counter(tag: str, label: str = 'cells') -> Callable[[int, int], None]:
    """A (done, total) callback that keeps one line on stderr up to date: ``[tag] done/total label``."""
    def show(done: int, total: int) -> None:
        sys.stderr.write(f'\r[{tag}] {done}/{total} {label}')
        if done == total:
            sys.stderr.write('\n')
        sys.stderr.flush()
    return show


def progress_lines(tag: str) -> Callable[[str], None]:
    """A message callback that prints ``[tag] <seconds since now> s  <message>`` lines on stderr."""
    t0 = time.perf_counter()

    def say(msg: str) -> None:
        print(f'[{tag}] {time.perf_counter() - t0:5.1f} s  {msg}', file=sys.stderr, flush=True)
    return say


def paper_row(label: str, entry: dict, fmt: str = '{:.4f}') -> str:
    """Two lines: ipfric's value of ``entry`` and the paper's (scalars or lists)."""
    ours, ref = entry['ipfric'], entry['paper']
    if isinstance(ours, list):
        ours = '[' + ', '.join(fmt.format(v) for v in ours) + ']'
        ref = '[' + ', '.join(fmt.format(v) for v in ref) + ']'
    else:
        ours, ref = fmt.format(ours), fmt.format(ref)
    return f'  {label:<34} ipfric {ours}\n  {"":<34} paper  {ref}'


def eig_text(pairs) -> str:
    """Eigenvalues given as (re, im) pairs, e.g. ``-1.2345, -0.5+2.1i``."""
    return ', '.join(f'{re:.4f}' + (f'{im:+.4f}i' if im else '') for re, im in pairs)
