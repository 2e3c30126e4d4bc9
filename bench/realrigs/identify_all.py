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

from .convert import LOGS

ROOT = Path(__file__).resolve().parents[2]
HEADER = ('| rig / log | exit | wall s | kept (effects, corrections, law) | verdict: motion left (floor) '
          '| final Fc, Fs - Fc [N] | on a bound |\n| --- | --- | --- | --- | --- | --- | --- |')


def identify(csv: Path, out: Path) -> dict:
    """Run ``./ipfric identify`` on one log; its exit code, wall time and the reason of a refusal."""
    with csv.open() as f:
        cart_alone = 'theta' not in f.readline().strip().split(',')
    cmd = [str(ROOT / 'ipfric'), 'identify', str(csv), '--plant', str(csv.parent / 'plant.yaml'), '--out', str(out),
           '--no-plots', '--json'] + (['--cart-alone'] if cart_alone else [])
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT, env=dict(os.environ, NUMBA_NUM_THREADS='1'), capture_output=True, text=True)
    run = dict(exit=proc.returncode, wall_s=round(time.perf_counter() - t0, 1), command='./ipfric ' + ' '.join(cmd[1:]))
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
    kept += [s['step'] for s in result['ladder'] if s['step'].endswith(' as declared')]
    v = result['verdict']
    params = {p['name']: p for p in result['ladder'][-1]['params']}
    friction = (f'{params["Fc"]["value"]:.3g}, {params["Fs_excess"]["value"]:.2g}' if 'Fc' in params
                else 'viscous law')
    bound = ', '.join(n for n, p in params.items() if p['at_bound']) or 'none'
    return dict(out, kept=', '.join(kept) or 'none', friction=friction, bound=bound,
                verdict=f'{"explained" if v["explained"] else "not explained"}: {v["unexplained_percent"]:.3g} % '
                        f'({v["floor_percent"]:.2g} %)')


def markdown(rows: list[dict]) -> str:
    return '\n'.join([HEADER] + [f'| {r["rig"]} / {r["log"]} | {r["exit"]} | {r["wall_s"]:.1f} | {r["kept"]} | '
                                 f'{r["verdict"]} | {r["friction"]} | {r["bound"]} |' for r in rows]) + '\n'


def identify_all(data: Path, runs: Path, only: list[str] | None = None, resume: bool = False) -> list[dict]:
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
                run = identify(csv, out)
            result = json.loads((out / 'result.json').read_text()) if run['exit'] == 0 else None
            rows.append(row(rig, log, run, result))
            print(markdown(rows[-1:]).split('\n')[-2], flush=True)
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
    args = ap.parse_args(argv)
    rows = identify_all(args.data.resolve(), args.out.resolve(), args.only.split(',') if args.only else None,
                        args.resume)
    print(f'\n{markdown(rows)}{len(rows)} logs; table in {args.out / "table.md"}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
