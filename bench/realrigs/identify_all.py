"""Identify every converted real-rig log, one at a time, and tabulate the answers as docs/identification.md does.

    python -m bench.realrigs.identify_all DIR --out RUNS [--only RIG[/LOG],...] [--resume]

For each ``DIR/<rig>/<log>.csv`` of :mod:`bench.realrigs.convert`, in the order of its table: ``./ipfric identify
LOG --plant DIR/<rig>/plant.yaml --out RUNS/<rig>/<log> --no-plots --json`` (``--cart-alone`` when the CSV has no
theta column) with NUMBA_NUM_THREADS=1; its exit code and wall time go to ``RUNS/<rig>/<log>/run.json``, and the
table of every log run (the doc's columns) to stdout, ``RUNS/table.md`` and ``RUNS/rows.json``. ``--resume`` skips
the logs whose result.json exists.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from .convert import LOGS, unknown_names

ROOT = Path(__file__).resolve().parents[2]
HEADER = ('| rig / log | exit | wall s | kept (effects, corrections, law) | verdict: motion left (floor) '
          '| final Fc, Fs - Fc [N] | on a bound |\n| --- | --- | --- | --- | --- | --- | --- |')


def identify(csv: Path, out: Path, time_limit: float | None = None) -> dict:
    """Run ``python -m ipfric_core.cli identify`` (``./ipfric identify``) on one log with this process's
    Python and environment, as the campaign does (the ipfric_core on its path: a worktree's where PYTHONPATH
    names it), on one thread (with ``--time-limit`` where ``time_limit`` [s] is given); its exit code, wall
    time and the reason of a refusal."""
    with csv.open() as f:
        cart_alone = 'theta' not in f.readline().strip().split(',')
    args = ['identify', str(csv), '--plant', str(csv.parent / 'plant.yaml'), '--out', str(out),
            '--no-plots', '--json'] + (['--cart-alone'] if cart_alone else []) + (
                ['--time-limit', f'{time_limit:g}'] if time_limit is not None else [])
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, '-m', 'ipfric_core.cli', *args], cwd=ROOT,
                          env=dict(os.environ, NUMBA_NUM_THREADS='1', OPENBLAS_NUM_THREADS='1', MKL_NUM_THREADS='1'),
                          capture_output=True, text=True)
    run = dict(exit=proc.returncode, wall_s=round(time.perf_counter() - t0, 1),
               command='python -m ipfric_core.cli ' + ' '.join(args))
    errors = [ln.split('error: ', 1)[1] for ln in proc.stderr.splitlines() if 'error: ' in ln]
    if proc.returncode:
        run['error'] = (errors[-1] if errors else proc.stderr.strip()[-300:]).replace(f'{csv.parent}/', '')
    out.mkdir(parents=True, exist_ok=True)
    (out / 'run.json').write_text(json.dumps(run, indent=1))
    return run


def row(rig: str, log: str, run: dict, result: dict | None) -> dict:
    """The doc's columns of one log: what the ladder kept, the verdict, the final friction levels, bounds."""
    out = dict(rig=rig, log=log, exit=run['exit'], wall_s=run['wall_s'])
    if result is None:
        return dict(out, kept='-', verdict=f'refused: {run.get("error", "no result.json")}', friction='-', bound='-')
    kept = [r['kept'] for r in result['rounds'] if r['kept']]
    for s in result['ladder']:
        if s['step'].startswith('- ') and s['step'][2:] in kept:      # an effect the ladder took back
            kept.remove(s['step'][2:])
    kept += [s['step'] for s in result['ladder'] if s['step'].endswith(' as declared')]
    kept += [f'{n} corrected' for n in result.get('constants_corrected', []) if f'{n} corrected' not in kept]
    v = result['verdict']
    params = {p['name']: p for p in result['ladder'][-1]['params']}
    def level(name: str, digits: int) -> str:
        p = params[name]
        return f'{p["value"]:.{digits}g}' + ('' if p['fitted'] else ' (held)')
    friction = f'{level("Fc", 3)}, {level("Fs_excess", 2)}' if 'Fc' in params else 'viscous law'
    bound = ', '.join(n for n, p in params.items() if p['at_bound']) or 'none'
    return dict(out, kept=', '.join(kept) or 'none', friction=friction, bound=bound,
                verdict=f'{"explained" if v["explained"] else "not explained"}: {v["unexplained_percent"]:.3g} % '
                        f'({v["floor_percent"]:.2g} %)' + (f'; stopped before round {v["stopped"]["before_round"]} '
                                                           f'(--time-limit {v["stopped"]["time_limit_s"]:g})'
                                                           if 'stopped' in v else ''))


def markdown(rows: list[dict]) -> str:
    return '\n'.join([HEADER] + [f'| {r["rig"]} / {r["log"]} | {r["exit"]} | {r["wall_s"]:.1f} | {r["kept"]} | '
                                 f'{r["verdict"]} | {r["friction"]} | {r["bound"]} |' for r in rows]) + '\n'


def identify_all(data: Path, runs: Path, only: list[str] | None = None, resume: bool = False,
                 time_limit: float | None = None) -> list[dict]:
    """Identify the logs of ``data`` (or those of ``only``) into ``runs``; the table's rows."""
    rows = []
    for rig, logs in LOGS.items():
        for log in logs:
            csv, out = data / rig / f'{log}.csv', runs / rig / log
            if (only and rig not in only and f'{rig}/{log}' not in only) or not csv.exists():
                continue
            if resume and (out / 'result.json').exists():    # run by hand before: no run.json
                run = json.loads((out / 'run.json').read_text()) if (out / 'run.json').exists() else \
                    dict(exit=0, wall_s=float('nan'))
            else:
                run = identify(csv, out, time_limit)
            result = json.loads((out / 'result.json').read_text()) if run['exit'] == 0 else None
            rows.append(row(rig, log, run, result))
            print(markdown(rows[-1:]).split('\n')[-2] if len(rows) > 1 else markdown(rows).rstrip(), flush=True)
    runs.mkdir(parents=True, exist_ok=True)
    (runs / 'rows.json').write_text(json.dumps(rows, indent=1))
    (runs / 'table.md').write_text(markdown(rows))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('data', type=Path, help='the directory bench.realrigs.convert wrote')
    ap.add_argument('--out', required=True, type=Path, help='directory of the reports, table.md and rows.json')
    ap.add_argument('--only', help='comma-separated rig or rig/log names (default: every log of DATA)')
    ap.add_argument('--resume', action='store_true', help='skip the logs whose result.json exists')
    ap.add_argument('--time-limit', type=float, metavar='SECONDS',
                    help='identify\'s --time-limit for each log (default: none)')
    args = ap.parse_args(argv)
    only = args.only.split(',') if args.only else None
    if why := unknown_names(only):
        ap.error(why)
    if not (args.data / 'manifest.json').is_file():
        ap.error(f'{args.data}: no manifest.json; give the directory that bench.realrigs.convert --out wrote')
    rows = identify_all(args.data.resolve(), args.out.resolve(), only, args.resume, args.time_limit)
    if not rows:
        ap.error(f'no converted log of {args.data} is among --only {args.only}')
    print(f'\n{markdown(rows)}{len(rows)} logs; table in {args.out / "table.md"}')
    failed = [f'{r["rig"]}/{r["log"]} (exit {r["exit"]})' for r in rows if r['exit'] not in (0, 2)]
    if failed:      # exit 2 is identify's refusal with its reason (too few windows): an answer, not a failure
        print(f'identify failed on {len(failed)} log(s): {", ".join(failed)}', file=sys.stderr)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
