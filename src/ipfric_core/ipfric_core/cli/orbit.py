"""``./ipfric orbit``: periodic orbits of a scenario's sampled closed loop found directly, the edge of the
upright's basin, and branches of orbits by continuation (:mod:`ipfric_core.study.orbit_study`)."""
from __future__ import annotations

import sys
import time

from ..run.scenario import DEFAULT_SCENARIO
from ..study.orbit_study import orbit_study
from ..study.variants import load_variant
from .output import output_dir, print_json
from .sweep import loop_variant_options

__all__ = ['NAME', 'HELP', 'add_arguments', 'main']

NAME = 'orbit'
HELP = ('periodic orbits of the sampled closed loop found directly (shooting on a Poincare section, Newton, '
        'Floquet multipliers), stable and unstable; --continue traces them over the delay, a gain scale or a '
        'friction scale (bifurcation diagram)')


def add_arguments(o) -> None:
    o.add_argument('--config', default=str(DEFAULT_SCENARIO), help='scenario (default %(default)s)')
    loop_variant_options(o)
    o.add_argument('--continue', dest='continue_', metavar='NAME=START:STOP[:POINTS]',
                   help='trace the branches of orbits over delay [s], gain or friction (multiples of the '
                   'scenario\'s gain, or of its mu_s, mu_c and eps) by continuation, first step 1/(POINTS-1) '
                   'of the range (default 100, at most 2000), e.g. delay=0:0.14; delays in [0, 10] s, friction >= 0')
    o.add_argument('--delay', type=float, default=None,
                   help='feedback delay [s] instead of the scenario\'s, in [0, 10]; it may fall between samples '
                   '(the --simulate run takes it to whole samples)')
    o.add_argument('--basin', metavar='LO,HI',
                   help='also find the edge of the upright\'s basin over the initial angle in [LO, HI] rad '
                   '(bisection: LO must settle, HI leave) and the unstable orbit the run at the edge lingers on; '
                   'with --continue its branch is traced too')
    o.add_argument('--duration', type=float, default=40.0,
                   help='with --basin: longest run [s] (default %(default)s; at most 2e6 samples, 2000 s at 1 kHz)')
    o.add_argument('--simulate', type=float, default=120.0,
                   help='also run the loop this many seconds and report its cycle beside the orbit (0 = no; '
                   'default %(default)s; at most 2e6 samples, 2000 s at 1 kHz)')
    o.add_argument('--scheduler', default=None, metavar='ADDRESS',
                   help='with --continue: compute the Jacobians\' columns on the Dask cluster whose scheduler '
                        'listens at ADDRESS (its workers run this project\'s environment); the same branches '
                        'as on this machine\'s cores')
    o.add_argument('--describing', action='store_true',
                   help='with --continue over delay or gain: the describing-function prediction on the diagram')
    o.add_argument('--no-plots', action='store_true', help='numbers only')
    o.add_argument('--out', default='runs/orbit', help='directory for orbit.json, branches.csv, bifurcation.png '
                   '(default %(default)s)')


def print_orbit(o: dict) -> None:
    print(f'  {"stable  " if o["stable"] else "unstable"} x p2p {100 * o["x_p2p_m"]:.4f} cm, theta p2p '
          f'{o["theta_p2p_rad"]:.3e} rad, period {o["period_s"]:.5f} s, stuck {100 * o["stuck_fraction"]:.1f} % '
          f'({o["sticks_per_period"]} sticking phases), largest multiplier |{o["max_multiplier_modulus"]:.3g}|')


def print_basin(b: dict, duration: float) -> None:
    print(f'  basin of the upright: runs from theta0 <= {b["settles_below_rad"]:.6g} rad settle, from '
          f'{b["leaves_from_rad"]:.6g} rad they leave ({b["runs"]} runs of up to {duration:g} s)')
    if not b['orbit']:
        print(f'    no periodic orbit at the edge: {b["no_orbit"]}')
        return
    o = b['orbit']
    f_lo, f_hi = b['shape_threshold']
    print(f'    the run at the edge lingers on the unstable orbit x p2p {100 * o["x_p2p_m"]:.4f} cm, theta '
          f'p2p {o["theta_p2p_rad"]:.4e} rad, period {o["period_s"]:.5f} s, largest multiplier '
          f'|{o["max_multiplier_modulus"]:.3g}|; the threshold is {b["threshold_over_orbit_amplitude"]:.3f} '
          f'of its angle amplitude')
    print(f'    starts of its shape settle up to {f_lo:.5f} and leave from {f_hi:.5f} times its size: '
          f'it bounds the basin')


def print_continuation(c: dict) -> None:
    print(f'  continuation in {c["parameter"]} over {c["range"][0]:g}:{c["range"][1]:g}: {c["points"]} orbits on '
          f'{c["branches"]} branches, {c["jacobians"]} Jacobians, {c["seconds"]} s')
    for e in c['events']:
        print(f'    branch {e["branch"]}: {e["event"]} at {e["parameter"]:.5g}' +
              (f' ({e["multiplier"]})' if 'multiplier' in e else ''))
    if 'plot' in c:
        print(f'  diagram: {c["plot"]}')


def main(args) -> int:
    output_dir(args.out)
    base = load_variant(args.config, args.sensors, args.smoothing, args.cutoff_hz)
    t0 = time.perf_counter()

    def progress(text):
        print(f'[orbit] {text} ({time.perf_counter() - t0:.1f} s)', file=sys.stderr, flush=True)
    res = orbit_study(base, args.out, args.delay, args.basin, args.duration, args.simulate, args.continue_,
                      args.scheduler, args.describing, not args.no_plots, None if args.json else progress,
                      {'config': args.config, 'sensors': args.sensors})
    if args.json:
        print_json(res)
        return 0
    print(f'Periodic orbits of {args.config} ({args.sensors} sensors, delay {res["delay_s"]:g} s), '
          f'{res["seconds"]:.2f} s')
    if 'no_orbit' in res:
        print(f'  none: {res["no_orbit"]}')
    for o in res['orbits']:
        print_orbit(o)
    if 'basin' in res:
        print_basin(res['basin'], args.duration)
    if 'simulation' in res:
        s = res['simulation']
        print(f'  simulation ({args.simulate:g} s, delay {s["delay_s"]:g} s, last half): x p2p '
              f'{100 * s["x_p2p_m"]:.4f} cm, period {s["period_s"]:.5f} s ({s["end_reason"]})')
    if 'continuation' in res:
        print_continuation(res['continuation'])
    print(f'  written: {res["files"]["json"]}')
    return 0
