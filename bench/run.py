"""``./ipfric bench``: every benchmark of ipfric beside its reference, run side by side.

Timings on a shared machine are noisy, so each target is a ratio to a reference measured
in the same run; absolute times are context. ``quick`` shrinks every benchmark to check
that it still runs (its numbers are not compared with the targets).
"""
from __future__ import annotations

import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ipfric_core.analysis.oscillation import classify, crossing_period
from ipfric_core.cli.output import print_json
from ipfric_core.constants import REPO_ROOT
from ipfric_core.physics.closedloop import run_closed_loop
from ipfric_core.run.scenario import load_scenario
from ipfric_core.study.executor import make_executor
from ipfric_core.study.montecarlo import parse_spread, run_chunk, run_montecarlo, spread_draw
from ipfric_core.study.sweep import parse_range, sweep
from ipfric_core.study.variants import cell_scenario, exact_sensors, scenario_at

CONFIG = REPO_ROOT / 'config'
EMPS = REPO_ROOT.parent / 'shared' / 'data' / 'emps'
ACCURACY = 0.005          # limit-cycle amplitude and period within 0.5 % of scipy
MUJOCO_STEPS = (1e-3, 5e-4, 2.5e-4)


def timed(fn, repeat: int = 1):
    """(median wall time [s], last result) of ``repeat`` calls."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def cycle(tr, settle: float) -> tuple[float, float | None]:
    """Limit cycle of a run: cart peak-to-peak [m] and period [s] after ``settle`` [s]."""
    late = tr.t >= settle
    return float(np.ptp(tr.state[late, 0])), crossing_period(tr.t[late], tr.state[late, 0])


def rel_error(a, b) -> float:
    """Largest relative difference of (amplitude, period) pairs; inf when a period is missing."""
    if a[1] is None or b[1] is None:
        return math.inf
    return max(abs(a[0] / b[0] - 1), abs(a[1] / b[1] - 1))


def machine() -> dict:
    cpu = 'unknown'
    try:
        cpu = next(line.split(':', 1)[1].strip() for line in open('/proc/cpuinfo') if line.startswith('model name'))
    except (OSError, StopIteration):
        pass
    mem = ''
    try:
        mem = next(line.split(':', 1)[1].strip() for line in open('/proc/meminfo') if line.startswith('MemTotal'))
    except (OSError, StopIteration):
        pass
    import mujoco
    import numba
    import scipy
    return {'cpu': cpu, 'cores': os.cpu_count(), 'memory': mem, 'kernel': platform.release(),
            'python': platform.python_version(), 'numpy': np.__version__, 'scipy': scipy.__version__,
            'numba': numba.__version__, 'mujoco': mujoco.__version__,
            'load_average_at_start': os.getloadavg(), 'date_utc': time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}


# ------------------------------------------------------------------------ offline closed loop
def bench_closed_loop(quick: bool) -> list[dict]:
    from .mujoco_reference import MujocoLoop
    from .scipy_reference import run_scipy
    base = load_scenario(CONFIG / 'fig7_old_gain_exponential.yaml')
    duration = 2.0 if quick else 20.0
    run_closed_loop(base.make_rig(), base.make_controller(), 0.01)  # compile / load the cache
    t_ipf, _ = timed(lambda: run_closed_loop(base.make_rig(), base.make_controller(), duration), 1 if quick else 7)
    t_sci, _ = timed(lambda: run_scipy(base, duration))
    # accuracy: exact sensors, where the limit cycle is a well-conditioned number (with the
    # encoders it moves by a few % between converged integrators); 30 s for several periods
    ex, span = exact_sensors(base), 2.0 if quick else 30.0
    settle = span / 3
    ref = cycle(run_scipy(ex, span), settle)
    ours = cycle(run_closed_loop(ex.make_rig(), ex.make_controller(), span), settle)
    err_ipf = rel_error(ours, ref)
    mj = []
    for h in MUJOCO_STEPS:
        loop = MujocoLoop(ex, h)
        mj.append((h, rel_error(cycle(loop.run(span), settle), ref)))
    good = [h for h, e in mj if e <= ACCURACY]
    h_mj = max(good) if good else min(MUJOCO_STEPS)
    err_mj = dict(mj)[h_mj]
    loop = MujocoLoop(base, h_mj)
    loop.run(0.01)
    t_mj, _ = timed(lambda: loop.run(duration), 1 if quick else 5)
    sweep_note = ', '.join(f'h {h * 1e3:g} ms: {100 * e:.3g} %' for h, e in mj)
    return [
        {'benchmark': f'closed loop {duration:g} s, Fig. 7 stick-slip, 1 kHz, encoders',
         'reference': f'scipy LSODA + events {t_sci:.3g} s', 'ipfric': f'{t_ipf * 1e3:.3g} ms',
         'ratio': t_sci / t_ipf, 'target': '>= 50x faster', 'met': t_sci / t_ipf >= 50},
        {'benchmark': f'closed loop {duration:g} s vs MuJoCo (fastest accurate: Euler h {h_mj * 1e3:g} ms)',
         'reference': f'MuJoCo {t_mj * 1e3:.3g} ms', 'ipfric': f'{t_ipf * 1e3:.3g} ms',
         'ratio': t_mj / t_ipf, 'target': 'faster than MuJoCo', 'met': t_mj / t_ipf > 1},
        {'benchmark': 'limit cycle error vs scipy (amplitude, period; exact sensors)',
         'reference': f'MuJoCo {100 * err_mj:.3g} % ({sweep_note})', 'ipfric': f'{100 * err_ipf:.2g} %',
         'ratio': None, 'target': '<= 0.5 %', 'met': err_ipf <= ACCURACY and good != []},
    ]


# ------------------------------------------------------------------------------------ sweep
_MJ: dict = {}   # the MuJoCo model of a process, built once


def _mujoco_cell(args):
    from .mujoco_reference import MujocoLoop
    base, tau, th, duration = args
    if 'loop' not in _MJ:
        _MJ['loop'] = MujocoLoop(base, 1e-3)
    tr = _MJ['loop'].run(duration, theta0=math.radians(th), delay=tau)
    scn = cell_scenario(base, tau, th)
    return classify(tr.t, tr.measured[:, 0], tr.measured[:, 1], (0.0, 0.0), scn.sim.fallen_angle,
                    ended_fallen=tr.end_reason != 'duration').cls


def bench_sweep(quick: bool) -> list[dict]:
    base = exact_sensors(load_scenario(CONFIG / 'fig9_new_gain_exponential.yaml'))
    taus = parse_range('0:0.01:0.005' if quick else '0:0.14:0.005')
    ths = parse_range('0:1:0.5' if quick else '0:12:0.5')
    duration = 2.0 if quick else 20.0
    with tempfile.TemporaryDirectory() as tmp:
        t_ipf, rows = timed(lambda: sweep(base, taus, ths, duration, tmp, workers=2))
    cells = [(base, float(t), float(th), duration) for th in ths for t in taus]
    with make_executor(None, 2) as pool:
        t_mj, classes = timed(lambda: list(pool.map(_mujoco_cell, cells, chunksize=max(1, len(cells) // 8))))
    agree = np.mean([r['class'] == c for r, c in zip(rows, classes)])
    ok = t_ipf < 10.0 and t_ipf < t_mj
    return [{'benchmark': f'Figure-11 sweep, {len(cells)} runs of {duration:g} s, 2 processes',
             'reference': f'MuJoCo {t_mj:.3g} s (same class in {100 * agree:.0f} % of cells)',
             'ipfric': f'{t_ipf:.3g} s', 'ratio': t_mj / t_ipf, 'target': '< 10 s and faster than MuJoCo',
             'met': ok}]


# ------------------------------------------------------------------------------ Monte Carlo
def bench_montecarlo(quick: bool) -> list[dict]:
    """./ipfric montecarlo's runs (Figure 7, friction levels and eps +/- 30 %, encoders) in 2 local
    processes, beside the same runs one after the other in this process."""
    base = load_scenario(CONFIG / 'fig7_old_gain_exponential.yaml')
    runs, duration = (10, 2.0) if quick else (1000, 20.0)
    spread = parse_spread('mu_s=0.3,mu_c=0.3,eps=0.3')

    def draw(i):
        return spread_draw(base, spread, 0, i)
    t_ipf, rows = timed(lambda: run_montecarlo(draw, runs, duration, workers=2))
    run_closed_loop(base.make_rig(), base.make_controller(), 0.01)  # compile / load the cache here too
    t_one, serial = timed(lambda: run_chunk([(i, *draw(i)) for i in range(runs)], duration))
    same = rows == serial
    return [{'benchmark': f'Monte Carlo, {runs} runs of {duration:g} s (Fig. 7, +/- 30 % friction), 2 processes',
             'reference': f'same runs in 1 process {t_one:.3g} s (same rows: {"yes" if same else "NO"})',
             'ipfric': f'{t_ipf:.3g} s', 'ratio': t_one / t_ipf, 'target': '< 15 s, rows as in 1 process',
             'met': t_ipf < 15.0 and same}]


# -------------------------------------------------------------------------------------- ROS
def _bare(mode: str, n: int) -> dict:
    """The JSON result of ``bench/ros_echo.py MODE N`` beside its echo, in a free ROS domain."""
    from ipfric_core.run.runner import claim_domain, ros_environment
    lock = claim_domain()
    env = ros_environment(lock.domain)
    script = str(Path(__file__).with_name('ros_echo.py'))
    echo = subprocess.Popen([sys.executable, script, 'echo'], env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        out = subprocess.run([sys.executable, script, mode, str(n)], env=env, capture_output=True, text=True,
                             timeout=120 + n / 500, check=True)
        return json.loads(out.stdout.strip().splitlines()[-1])
    finally:
        echo.send_signal(2)
        try:
            echo.wait(10)
        except subprocess.TimeoutExpired:
            echo.kill()
        lock.release()


def _load() -> str:
    return f'load {os.getloadavg()[0]:.2f}'


def bench_ros(quick: bool, realtime_s: float, work: Path) -> tuple[list[dict], Path]:
    """Lockstep beside the raw round trip; the realtime loop beside a bare rclpy 1 kHz deadline loop,
    each pair measured one after the other in this run (the load average at the start of each)."""
    from ipfric_core.run.runner import run
    load_lock = _load()
    lock = run(CONFIG / 'default.yaml', work / 'lockstep', 1.0 if quick else 20.0)
    load_echo = _load()
    echo = _bare('ping', 500 if quick else 5000)['per_s']
    steps = lock.steps_per_s or 0.0
    rows = [{'benchmark': f'ROS lockstep loop, sim + controller + recorder ({lock.samples} samples, {load_lock})',
             'reference': f'raw rclpy round trip {echo:.0f}/s ({load_echo})', 'ipfric': f'{steps:.0f} steps/s',
             'ratio': steps / echo, 'target': '>= 1000/s and >= 0.8x raw',
             'met': steps >= 1000 and steps >= 0.8 * echo}]
    n = int(realtime_s * 1000)
    load_bare = _load()
    bare = _bare('deadline', n)
    load_rt = _load()
    rt = run(CONFIG / 'realtime.yaml', work / 'realtime', realtime_s)
    res = json.loads((work / 'realtime' / 'sim_result.json').read_text())
    lat, b = res['command_latency_s'], bare['latency_s'] or {}
    stale, bare_stale = res['samples_without_command'] / res['samples'], bare['stale'] / bare['samples']
    text = (f'{100 * stale:.3g} % stale ({res["samples_without_command"]} of {res["samples"]}); latency median '
            f'{lat["median"] * 1e3:.3g} / p99 {lat["p99"] * 1e3:.3g} (max {lat["max"] * 1e3:.3g}) ms; {load_rt}; '
            f'bag complete: {"yes" if rt.counts_match else "NO"}; tuning {res.get("tuning")}'
            if lat['commands'] else 'no commands')
    rows.append({'benchmark': f'ROS realtime 1 kHz, {realtime_s:g} s (config/realtime.yaml): stale samples, '
                              f'command latency',
                 'reference': f'bare rclpy 1 kHz deadline loop: {100 * bare_stale:.3g} % stale ({bare["stale"]} of '
                              f'{bare["samples"]}); latency median {b.get("median", 0) * 1e3:.3g} / p99 '
                              f'{b.get("p99", 0) * 1e3:.3g} (max {b.get("max", 0) * 1e3:.3g}) ms; {load_bare}',
                 'ipfric': text, 'ratio': stale / bare_stale if bare_stale else None,
                 'target': 'stale <= 2x the bare loop\'s and < 0.1 % (idle machine), p99 < 0.5 ms',
                 'met': bool(lat['commands']) and stale <= max(2 * bare_stale, 1 / res['samples']) and stale < 1e-3
                 and lat['p99'] < 5e-4 and rt.exit_code == 0})
    return rows, Path(rt.bag)


def _analyze(bag: Path) -> tuple[float, float, int]:
    """(wall [s], peak RSS [MB], samples) of ./ipfric analyze --no-plots in a process of its own."""
    cmd = [sys.executable, '-m', 'ipfric_core.cli', 'analyze', str(bag), '--no-plots', '--json']
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    assert proc.stdout is not None
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        raise RuntimeError(f'analyze {bag} failed (status {status})')
    return wall, usage.ru_maxrss / 1024, json.loads(out)['runs'][0]['samples']


def bench_analyze(bag: Path, small: Path, minutes: float) -> list[dict]:
    """./ipfric analyze on the realtime run's bag, beside the same on the short lockstep bag."""
    t_small, rss_small, n_small = _analyze(small)
    wall, rss, samples = _analyze(bag)
    size = sum(f.stat().st_size for f in Path(bag).glob('*.mcap')) / 1e6
    return [{'benchmark': f'analyze a {minutes:.3g}-min 1 kHz bag ({size:.0f} MB, {samples} samples)',
             'reference': f'{n_small}-sample bag: {t_small:.3g} s, peak RSS {rss_small:.0f} MB',
             'ipfric': f'{wall:.3g} s, peak RSS {rss:.0f} MB', 'ratio': None,
             'target': '< 5 s, bounded memory', 'met': wall < 5.0 and rss - rss_small < size}]


#: one simulation of the 2-minute record's estimation part (its first 60 %, 72000 samples: the cart's and
#: the angle's windows) took about 28 ms of CPU when the identification's target of 60 s was met
#: (docs/performance.md, 2026-11-25): 60 s is about 2100 such simulations, a target that moves with the machine
SIMULATIONS_IN_60_S = 2100


def simulation_time(record: Path, repeats: int = 15, law: str = 'exponential', values: dict | None = None,
                    effect: str | None = None) -> float:
    """The median wall time [s] of one simulation of ``record``'s estimation part (identify's default
    split) with its declared model (the paper's ``law``, Table 1's plant; ``values`` in place of some
    of its parameters, or the parameters of ``effect`` added to it): every window of the cart and of the
    angle replayed once, the unit of the identification's work (``ident/shooting.predict``), measured in
    this process after a first call that compiles."""
    from ipfric_core.analysis.records import load
    from ipfric_core.ident import shooting
    from ipfric_core.ident.model import declared, read_declared
    from ipfric_core.physics.params import PlantParams
    plant, friction = read_declared(None, law)
    rec = load(record, plant).split(0.6)[0]
    base = declared(plant or rec.plant or PlantParams(), friction, rec.theta is not None)
    model = (base.with_effect(effect, values) if effect else base.with_values(values or {})).vectors()
    windows = [shooting.cart_windows(rec)] + ([shooting.angle_windows(rec)] if rec.theta is not None else [])

    def once() -> float:
        t0 = time.perf_counter()
        for w in windows:
            shooting.predict(model, rec, w)
        return time.perf_counter() - t0
    once()
    return statistics.median(once() for _ in range(repeats))


def bench_identify(quick: bool) -> list[dict]:
    """./ipfric identify on the EMPS files and on a 2-minute 1 kHz closed-loop record of the
    independent rig simulator (tests/independent), if this tree has that command; the record's row
    beside one simulation of it, measured in the same run (the ratio: simulations' worth of work)."""
    base = [sys.executable, '-m', 'ipfric_core.cli', 'identify']
    helped = subprocess.run(base + ['--help'], capture_output=True, text=True)
    out_dir = REPO_ROOT / 'runs' / 'bench-identify'
    cases = [('identify on EMPS (both files, full effect search)',
              [str(EMPS / 'DATA_EMPS.mat'), '--test', str(EMPS / 'DATA_EMPS_PULSES.mat')]),
             ('identify on a 2-min 1 kHz closed-loop record (independent simulator, cogging)', None)]
    rows = []
    for name, args in cases:
        row: dict = {'benchmark': name, 'reference': '-', 'ratio': None, 'target': '< 60 s'}
        if helped.returncode != 0:
            rows.append({**row, 'ipfric': 'not available (no identify command)', 'met': None})
            continue
        if quick:
            rows.append({**row, 'ipfric': 'available (not run in quick mode)', 'met': None})
            continue
        sim = None
        if args is None:
            from bench.independent_code import rigsim
            args = [str(rigsim.write_case('loop_cogging', out_dir, duration=120.0))]
            sim = simulation_time(Path(args[0]))
            row.update(reference=f'one simulation of the record\'s estimation part: {1e3 * sim:.3g} ms',
                       target=f'< {SIMULATIONS_IN_60_S} simulations\' worth (the 60 s target at the 28 ms a '
                              f'simulation took on the machine it was set on)')
        t0 = time.perf_counter()
        out = subprocess.run(base + args + ['--out', str(out_dir / ('emps' if args[0].endswith('.mat') else 'loop')),
                                            '--json', '--no-plots'],
                             capture_output=True, text=True, timeout=1800)
        wall = time.perf_counter() - t0
        if out.returncode != 0:
            tail = (out.stderr.strip().splitlines() or ['?'])[-1]
            rows.append({**row, 'ipfric': f'failed after {wall:.3g} s: {tail}', 'met': False})
        elif sim is None:
            rows.append({**row, 'ipfric': f'{wall:.3g} s', 'met': wall < 60.0})
        else:
            ratio = wall / sim
            rows.append({**row, 'ipfric': f'{wall:.3g} s, {ratio:.0f} simulations\' worth', 'ratio': round(ratio),
                         'met': ratio < SIMULATIONS_IN_60_S})
    return rows


#: bristles as stiff as the ladder fits them (its sigma0 bound on real logs reaches 5e5 N/m) [N/m]
STIFF_SIGMA0 = 4e5
#: a simulation of the dynamic law may cost this many times the exponential law's
BRISTLE_COST = 4.0


def bench_bristles(quick: bool) -> dict:
    """One simulation of the 2-minute closed-loop record (20 s in quick mode) with the dynamic law's
    bristles at STIFF_SIGMA0, beside the exponential law's in the same run: the bristles relax at
    sigma0 |v| / g(v), up to 1e5 /s, a rate the RK4 steps must follow (``simulate.bristle_step``)."""
    from bench.independent_code import rigsim
    from ipfric_core.physics.params import PlantParams
    record = rigsim.write_case('loop_cogging', REPO_ROOT / 'runs' / 'bench-bristles', duration=20.0 if quick else 120.0)
    repeats = 3 if quick else 15
    ref = simulation_time(record, repeats)
    # damped critically on Table 1's cart, as ``ident/starts.bristle_starts`` starts them
    stiff = {'sigma0': STIFF_SIGMA0, 'sigma1': 2 * math.sqrt(STIFF_SIGMA0 * PlantParams().M)}
    dyn = simulation_time(record, repeats, 'dynamic', stiff)
    return {'benchmark': f'one simulation of the {"20-s" if quick else "2-min"} 1 kHz closed-loop record\'s estimation '
                         f'part, dynamic law with stiff bristles (sigma0 {STIFF_SIGMA0:.0e} N/m)',
            'reference': f'exponential law {1e3 * ref:.3g} ms', 'ipfric': f'{1e3 * dyn:.3g} ms',
            'ratio': round(dyn / ref, 2), 'target': f'<= {BRISTLE_COST:g}x the exponential law',
            'met': dyn <= BRISTLE_COST * ref}


#: a simulation with a drive with play may cost this many times one without it: its contact rings at 180 Hz
#: and takes CONTACT_STEPS steps a period, 7 a 1 kHz sample of Heun pairs where the record's model takes one
#: RK4 step (about 9 times the work), and each window of the cart runs a lead of 1 s (up to half as much again)
DRIVE_COST = 15.0


def bench_drive(quick: bool) -> dict:
    """One simulation of the independent simulator's balancing loop on a drive with play (its true drive:
    rigsim.EFFECTS['backlash'], 1 mm, 0.2 kg behind a 2e5 N/m contact, 30 s; 20 s in quick mode) beside the
    same record's simulation without the drive, in the same run: the contact's oscillation sets the steps
    (``simulate.drive_step``), finer where the contact closes or opens (``simulate.advance_drive``)."""
    from bench.ident_campaign import drive_values
    from bench.independent_code import rigsim
    record = rigsim.write_case('loop_backlash', REPO_ROOT / 'runs' / 'bench-drive', duration=20.0 if quick else 30.0)
    repeats = 3 if quick else 15
    ref = simulation_time(record, repeats)
    true = drive_values(rigsim.EFFECTS['backlash'])
    with_drive = simulation_time(record, repeats, effect='drive_backlash', values=true)
    return {'benchmark': f'one simulation of a {"20-s" if quick else "30-s"} 1 kHz balancing loop\'s estimation part '
                         'with its drive with play (1 mm, 0.2 kg, 2e5 N/m)',
            'reference': f'the same record without the drive {1e3 * ref:.3g} ms',
            'ipfric': f'{1e3 * with_drive:.3g} ms',
            'ratio': round(with_drive / ref, 2), 'target': f'<= {DRIVE_COST:g}x the record without the drive',
            'met': with_drive <= DRIVE_COST * ref}


def bench_campaign(quick: bool, n_cases: int, seed: int = 1) -> list[dict]:
    """The randomised identification campaign (bench/ident_campaign.py: cases drawn by independent code,
    each through ./ipfric identify), its confusion matrix in runs/bench-campaign/summary.md."""
    from bench import ident_campaign
    n = 1 if quick else n_cases
    out = REPO_ROOT / 'runs' / ('bench-campaign-quick' if quick else 'bench-campaign')
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.perf_counter()
    s = ident_campaign.run_campaign(out, n, seed, workers=min(n, os.cpu_count() or 1),
                                    progress=lambda msg: print(msg, file=sys.stderr), duration=30.0 if quick else None)
    tg = ident_campaign.targets(s)
    share = tg['right_share_above_limit']
    met = (n >= 200 and share is not None and share >= 0.95 and (tg['clean_share_anything_added'] or 0.0) <= 0.02
           and tg['outside_under_library_name'] == 0)
    cases = f'{n} case{"s" if n != 1 else ""}'
    return [{'benchmark': f'identification campaign: {cases} of independent code (seed {seed}), '
                          f'confusion matrix in {out.relative_to(REPO_ROOT)}/summary.md',
             'reference': 'the truth each case was drawn with',
             'ipfric': f'right {tg["right_above_limit"]} of {tg["above_limit"]} above the detection limits; clean '
                       f'with anything added {100 * (tg["clean_share_anything_added"] or 0.0):.3g} %; outside the '
                       f'library: {tg["outside_not_explained"]} of {tg["outside"]} not explained, '
                       f'{tg["outside_under_library_name"]} under a library name; {time.perf_counter() - t0:.0f} s',
             'ratio': share, 'target': '>= 200 cases; >= 95 % right above the limits, <= 2 % of clean cases with '
                                       'anything added, none from outside the library under a library name',
             'met': met}]


# ----------------------------------------------------------------------------------- orbits
def bench_orbit(quick: bool) -> list[dict]:
    """./ipfric orbit on Figure 7 (exact sensors): one orbit beside the 120 s run whose cycle it
    predicts, and the branch over the delay 0-0.14 s (100 points) beside 100 runs of 20 s."""
    from ipfric_core.study.continuation import trace
    from ipfric_core.study.orbit import find_orbit, simulated_cycle
    from ipfric_core.study.variants import loop_of
    base = exact_sensors(load_scenario(CONFIG / 'fig7_old_gain_exponential.yaml'))
    find_orbit(loop_of(base, 'delay', 0.0))                       # compile / load the cache
    t_orbit, orbit = timed(lambda: find_orbit(loop_of(base, 'delay', 0.0)), repeat=3)
    long_run = 20.0 if quick else 120.0
    t_sim, sim = timed(lambda: simulated_cycle(base.make_rig(), base.make_controller(), long_run))
    err = max(abs(orbit.x_p2p / sim['x_p2p_m'] - 1), abs(orbit.period / sim['period_s'] - 1))
    rows = [{'benchmark': 'one periodic orbit (Figure 7, exact sensors; shooting, Newton, multipliers)',
             'reference': f'{long_run:g} s run {t_sim:.3g} s (orbit within {100 * err:.3g} % of its cycle)',
             'ipfric': f'{t_orbit:.3g} s', 'ratio': t_sim / t_orbit, 'target': '< 1 s, within 0.1 % of the run',
             'met': t_orbit < 1.0 and err < 1e-3}]
    stop, points, runs = (0.01, 5, 5) if quick else (0.14, 100, 100)
    t_branch, found = timed(lambda: trace(lambda v: loop_of(base, 'delay', v), 0.0, stop, points))
    cells = [scenario_at(base, 'delay', stop * i / (runs - 1)) for i in range(runs)]
    t_runs, _ = timed(lambda: [run_closed_loop(c.make_rig(), c.make_controller(), 20.0) for c in cells])
    per_100 = 100.0 * t_branch / max(len(found.points), 1)
    folds = ', '.join(f'{1e3 * e["parameter"]:.2f}' for e in found.events if e['event'] == 'fold')
    rows.append({'benchmark': f'orbit branches over the delay 0-{stop:g} s (Figure 7, as `orbit --continue '
                              f'delay=0:{stop:g}:{points}`)',
                 'reference': f'{runs} runs of 20 s {t_runs:.3g} s',
                 'ipfric': f'{t_branch:.3g} s: {len(found.points)} orbits ({per_100:.3g} s per 100), '
                           f'{found.jacobians} Jacobians; folds at {folds or "none"} ms',
                 'ratio': t_runs / t_branch, 'target': '< 30 s per 100 orbits', 'met': per_100 < 30.0})
    rows.append(bench_basin())
    return rows


def bench_basin() -> dict:
    """The unstable orbit on the edge of the upright's basin (gain (23), exponential friction with
    tanh(100 v), delay 90 ms, exact sensors) beside the bisection of theta0 by `sweep --threshold`:
    the starts of the orbit's shape scaled by f settle below f* and fall above; f* against 1."""
    from ipfric_core.study.basin import basin_edge, shape_threshold
    from ipfric_core.study.sweep import threshold_angle
    from ipfric_core.study.variants import loop_of
    base = exact_sensors(load_scenario(CONFIG / 'fig9_new_gain_exponential.yaml'))
    base = replace(base, friction=base.friction.replace(smoothing='tanh'))
    base = scenario_at(base, 'delay', 0.09)
    t_bisect, sweep = timed(lambda: threshold_angle(base, math.radians(0.05), math.radians(0.1), 40.0))

    def edge_and_shape():
        edge = basin_edge(lambda a: loop_of(base, 'theta0', a), 1e-4, 0.03)
        return edge, shape_threshold(loop_of(base, 'theta0', edge.settles_below), edge.orbit)
    t_edge, (edge, (f_lo, f_hi)) = timed(edge_and_shape)
    o = edge.orbit
    off = max(abs(f_lo - 1), abs(f_hi - 1))
    inside = sweep['settles_below_rad'] <= edge.settles_below <= sweep['oscillates_from_rad']
    return {'benchmark': 'unstable orbit on the edge of the upright\'s basin (gain (23), tanh, delay 90 ms)',
            'reference': f'sweep --threshold {t_bisect:.3g} s: theta0 {sweep["settles_below_rad"]:.5g}-'
                         f'{sweep["oscillates_from_rad"]:.5g} rad ({sweep["runs"]} runs of 40 s)',
            'ipfric': f'{t_edge:.3g} s: x p2p {1e3 * o.x_p2p:.4g} mm, multiplier {o.largest_multiplier:.3g}; '
                      f'starts of its shape settle to {f_lo:.5f} and fall from {f_hi:.5f} times its size; '
                      f'theta0 threshold {edge.settles_below:.6g} rad '
                      f'({edge.settles_below / (0.5 * o.theta_p2p):.3f} of its angle amplitude)',
            'ratio': t_bisect / t_edge, 'target': 'orbit size within 5 % of the bisection threshold',
            'met': off < 0.05 and inside}


# ------------------------------------------------------------------------------------ table
COLUMNS = ('benchmark', 'reference', 'ipfric', 'ratio', 'target', 'met')


def cell(row, key, quick) -> str:
    v = row.get(key)
    if key == 'ratio':
        return '-' if v is None else f'{v:.3g}x'
    if key == 'met':
        if v is None:
            return 'n/a'
        return 'ran' if quick else ('met' if v else 'missed')
    return str(v)


def table(rows, quick) -> str:
    lines = ['| ' + ' | '.join(COLUMNS) + ' |', '|' + '---|' * len(COLUMNS)]
    lines += ['| ' + ' | '.join(cell(r, k, quick) for k in COLUMNS) + ' |' for r in rows]
    return '\n'.join(lines)


def run_all(quick: bool = False, realtime_s: float = 600.0, results: Path | None = None,
            progress=print, campaign_cases: int = 200) -> dict:
    """Run every benchmark; write the table with the machine's description to ``results``."""
    info = machine()
    rows = []
    work = REPO_ROOT / 'runs' / ('bench-quick' if quick else 'bench') / 'work'  # the ROS runs, kept
    shutil.rmtree(work, ignore_errors=True)
    for name, fn in (('closed loop', lambda: bench_closed_loop(quick)), ('sweep', lambda: bench_sweep(quick)),
                     ('Monte Carlo', lambda: bench_montecarlo(quick)), ('orbits', lambda: bench_orbit(quick))):
        progress(f'[bench] {name} ...')
        rows += fn()
    progress('[bench] ROS lockstep, rclpy round trip, realtime ...')
    ros_rows, bag = bench_ros(quick, 2.0 if quick else realtime_s, work)
    rows += ros_rows
    progress('[bench] analyze ...')
    rows += bench_analyze(bag, work / 'lockstep' / 'bag', (2.0 if quick else realtime_s) / 60)
    progress('[bench] identify ...')
    rows += bench_identify(quick)
    progress('[bench] dynamic law with stiff bristles ...')
    rows.append(bench_bristles(quick))
    progress('[bench] a drive with play ...')
    rows.append(bench_drive(quick))
    progress(f'[bench] identification campaign ({1 if quick else campaign_cases} cases) ...')
    rows += bench_campaign(quick, campaign_cases)
    info['load_average_at_end'] = os.getloadavg()
    text = table(rows, quick)
    if results is not None:
        results.parent.mkdir(parents=True, exist_ok=True)
        results.write_text(
            f'# ipfric benchmarks{" (quick: checks that they run, no targets)" if quick else ""}\n\n'
            f'`./ipfric bench{" --quick" if quick else ""}`, {info["date_utc"]}. Ratios are measured side by side '
            f'in the same run; the machine is shared, so absolute times are context only.\n\n'
            f'Machine: {info["cpu"]}, {info["cores"]} cores, {info["memory"]}, Linux {info["kernel"]}; '
            f'Python {info["python"]}, numpy {info["numpy"]}, scipy {info["scipy"]}, numba {info["numba"]}, '
            f'mujoco {info["mujoco"]}; load average {info["load_average_at_start"][0]:.2f} at start, '
            f'{info["load_average_at_end"][0]:.2f} at end. What each row measures and where the time '
            f'goes: docs/performance.md.\n\n{text}\n')
    return {'quick': quick, 'machine': info, 'rows': rows, 'table': text,
            'results': str(results) if results else None}


def main(argv=None) -> int:
    """``python -m bench.run [--quick] [--realtime-duration S] [--campaign-cases N] [--results FILE] [--json]`` (what
    ``./ipfric bench`` runs): the table on stdout, or the whole result as JSON."""
    import argparse
    p = argparse.ArgumentParser(prog='python -m bench.run', description=main.__doc__)
    p.add_argument('--quick', action='store_true')
    p.add_argument('--realtime-duration', type=float, default=600.0)
    p.add_argument('--campaign-cases', type=int, default=200,
                   help='cases of the identification campaign (default 200: about three hours on two cores, '
                        'one case per core; --quick: one)')
    p.add_argument('--results', type=Path, required=True)
    p.add_argument('--json', action='store_true')
    a = p.parse_args(argv)
    if a.campaign_cases < 1:
        p.error(f'--campaign-cases: {a.campaign_cases} is out of range; allowed: 1 or more')
    out = run_all(a.quick, a.realtime_duration, a.results, progress=lambda msg: print(msg, file=sys.stderr),
                  campaign_cases=a.campaign_cases)
    if a.json:
        print_json(out)
    else:
        print(out['table'])
        print(f'written: {out["results"]}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
