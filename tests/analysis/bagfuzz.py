"""Read damaged copies of one bag (a subprocess of test_bagread_fuzz: a crash shows as a signal).

``python bagfuzz.py BAG SEED CUTS FLIPS WORKDIR``: for each case, a copy of BAG cut at a
random length or with one random byte changed (numpy generator seeded with SEED) is read
with ``read_run`` and analysed with ``ipfric analyze``; prints ``start <case>`` before and
one JSON line after each case: kind, offset, exit code of analyze, what the reader reported
and how the values read compare with those of the undamaged bag.
"""
import contextlib
import io
import json
import sys
from pathlib import Path

import numpy as np

from ipfric_core.analysis.bagread import read_run
from ipfric_core.cli import main
from ipfric_core.physics.params import ConfigError


def rows(run) -> dict:
    """Every value of a run, as sets of rows per stream (bytes of float64 rows)."""
    tables = {'joint_states': np.column_stack([run.t, run.x, run.theta]),
              'voltage_command': np.column_stack([run.command_t, run.voltage]),
              'plant_state': np.column_stack([run.truth_t] + [run.truth[k] for k in sorted(run.truth)])}
    return {k: [r.tobytes() for r in v] for k, v in tables.items()}


def compare(run, ref, ref_rows) -> tuple[bool, bool]:
    """(identical, subset): every value equals the original, or every row read is an original row."""
    got = rows(run)
    same = (got == ref_rows and run.events == ref.events and run.gain == ref.gain and run.config == ref.config
            and run.counts == ref.counts)
    subset = (all(set(got[k]) <= set(ref_rows[k]) for k in got) and set(run.events) <= set(ref.events)
              and run.gain in (None, ref.gain) and run.config in (None, ref.config))
    return same, subset


def analyze_exit(path: Path) -> int:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        return main(['analyze', '--no-plots', '--json', str(path)])


def main_fuzz(bag, seed, cuts, flips, work) -> None:
    data = Path(bag).read_bytes()
    ref = read_run(bag)
    ref_rows = rows(ref)
    rng = np.random.default_rng(seed)
    cases = [('cut', int(rng.integers(0, len(data)))) for _ in range(cuts)]
    cases += [('flip', int(rng.integers(0, len(data)))) for _ in range(flips)]
    masks = rng.integers(1, 256, size=len(cases))
    path = Path(work) / 'case.mcap'
    for k, ((kind, at), mask) in enumerate(zip(cases, masks)):
        print(f'start {k} {kind} {at}', flush=True)
        if kind == 'cut':
            damaged = data[:at]
        else:
            damaged = bytearray(data)
            damaged[at] ^= int(mask)
        path.write_bytes(bytes(damaged))
        out = {'case': k, 'kind': kind, 'at': at, 'exit': analyze_exit(path)}
        try:
            run = read_run(path)
        except ConfigError as exc:
            out.update(refused=str(exc))
        else:
            same, subset = compare(run, ref, ref_rows)
            out.update(intact=run.intact, same=same, subset=subset, samples=len(run.t),
                       report=[run.truncation_detail] + run.damage)
        print(json.dumps(out), flush=True)


if __name__ == '__main__':
    main_fuzz(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5])
