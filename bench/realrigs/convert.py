"""Convert the public real-rig logs of docs/identification.md ("Real rigs") for ``./ipfric identify``.

    python -m bench.realrigs.convert --out DIR [--mirror /work/.mirror] [--only RIG[/LOG],...]

Fetches nothing: it reads the repository snapshots the ``fetch`` tool brought under the mirror root
(``<owner>+<name>/repo``, a bare git directory; a log deleted since is read from the last commit that
holds it) and writes, per rig, ``DIR/<rig>/plant.yaml`` and ``DIR/<rig>/<log>.csv`` with the columns
``t,x,voltage[,theta]`` (s from the first row, m, V, rad; theta left out where no angle was logged),
and ``DIR/manifest.json`` (source commit, rows, duration and median sample period of each log).
Most of these logs state no licence: keep DIR out of the repository.

One function per rig reads its logs (the units each one writes are said there, from the code that
wrote or read them); :data:`LOGS` names every log with its repository path and notes, :data:`PLANTS`
the rig's constants with the file each comes from.
"""
from __future__ import annotations

import argparse
import csv
import io
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import scipy.io

MIRROR = Path('/work/.mirror')
ROOT = Path(__file__).resolve().parents[2]
G = 9.81


def motor(kt: float, ke: float, ohm: float, radius: float, ratio: float = 1.0) -> dict:
    """alpha = kt n / (R r) [N/V] and the back-EMF damping beta = kt ke n^2 / (R r^2) [N s/m] of a DC
    motor (torque and EMF constants, armature resistance, pinion radius, gear ratio n) driving the cart."""
    return dict(alpha=kt * ratio / (ohm * radius), beta=kt * ke * ratio ** 2 / (ohm * radius ** 2))


#: per rig: its repository, the files its constants come from and the constants (M cart, m pendulum [kg],
#: l pivot to the pendulum's centre of mass [m], motor force alpha V - beta x' [N/V, N s/m])
PLANTS = {
    'utokyo_keisu_cartpend': (
        'ciesle/Enshu-git', 'keisu_jikken/touritsu/cartpend_OptimalRegulator.m: M identified, pendulum 42 cm '
        '(l its half), Ktau = Ke = 0.023, Kg = 1, 8.3 Ohm, pinion 6.35 mm; their identified Dhatx = 2.88 N s/m '
        'lumps the friction in, beta is the motor\'s back-EMF alone',
        dict(M=0.9473, m=0.0568, l=0.21, **motor(0.023, 0.023, 8.3, 0.00635))),
    'uc_enme403_pendulum': (
        'alexmchughnz/ENME403-lab', 'inverted_pendulum.m (the same in mcdiarmid/enme403-control-systems-lab '
        'pendulum.py): Mc, Mp, Lp, R = 0.16 Ohm, r = 18.4 mm, kg = 3.71, km = 0.0168; pendulum.py warns that '
        'the real values will likely differ, and R looks ten times low (the same lab\'s ENME303 motor, of '
        'nearly the same km and kg, has 1.5 Ohm): alpha may be ten times too high',
        dict(M=1.608, m=0.215, l=0.314, **motor(0.0168, 0.0168, 0.16, 0.0184, 3.71))),
    'uc_enme303_cart': (
        'Oshlo/ENME303-PID-Control-Assignment', 'enme303-lab-results/PID.m: M_c = 1.5 kg, K_m = 0.017, '
        'K_g = 3.7, R = 1.5 Ohm, r = 18 mm (its D = 7 N s/m is friction, not the motor); no pendulum on this '
        'rig (--cart-alone): m, l are the same lab\'s ENME403 pendulum, unused',
        dict(M=1.5, m=0.215, l=0.314, **motor(0.017, 0.017, 1.5, 0.018, 3.7))),
    'uoft_ip02_sip': (
        'richkejie/ece557-labs', 'Lab4/ece557-lab4/lab4.m (from lab 3): M, m, l, alpha_1 [N/V], alpha_2 [N s/m]',
        dict(M=1.1911, m=0.23, l=0.3302, alpha=1.7265, beta=10.5)),
    'sensorsini_cartpole': (
        'SensorsINI/physical-cartpole', 'Driver/config.yml at git-revision 2fb72d9 (the one the 2022 logs name): '
        'M 0.230, m 0.087, L 0.395/2 (half length), u_max 2.62 N at Q = 1, M_fric 4.77 N s/m (the motor\'s '
        'damping and the rolling friction, lumped: beta); PhysicalCartPoleDriver.py there sends Q as '
        '4307.69 Q PWM counts of a full scale of 8192 from a 12 V supply (README), so alpha = '
        'u_max 8192 / (12 V 4307.69); the 2023 calibration (b35b20c: 3617.43 of 7199) gives 0.435 N/V',
        dict(M=0.230, m=0.087, l=0.395 / 2, alpha=2.62 * 8192 / (12.0 * 4307.69), beta=4.77)),
    'kawata_cdip': (
        'Prof-Carter/book_ip', 'mfiles/p1c2/cdip_para2.m and ip_toolbox_1.0.2/iptools/cdip_para.m: the cart '
        'z\'\' = -ac z\' + bc v (ac = 6.25 1/s, bc = 4.362 m/s^2/V), mp, lp; the book gives no cart mass: '
        'M = 1 kg scales alpha = bc M and beta = ac M',
        dict(M=1.0, m=0.107, l=0.23, alpha=4.362, beta=6.25)),
    'aalborg_cart': (
        'nielsSkov/masterThesisMatlab', 'cartPendulum/initCartPendulum.m: M = 6.28 kg (estimated), r = 28 mm, '
        'k_tau = 93.4e-3 N m/A; the drive is current-controlled: the "voltage" column holds the current '
        'command [A], alpha = k_tau / r [N/A] (parameterEstimation/simCart.m) and beta = 0; m, l of its '
        'pendulum 1, unused (--cart-alone)',
        dict(M=6.28, m=0.2235, l=0.31692, alpha=93.4e-3 / 0.028, beta=0.0)),
    'labcontrole_esp32_cartpend': (
        'LaboratorioControle/classic-inverted-pendulum-mpc', 'params/params_pendulum.m (the TCC\'s): cart 370.2 g, '
        'rod 76.4 g, l = 0.18 m, Kt = 0.1336, Kb = 0.2842, Rm = 10.6919 Ohm, R = 19.8 mm (alpha = Kt / (Rm R), '
        'beta = Kt Kb / (Rm R^2) as in params_ss_pendulum.m; its c = 8.006 N s/m is friction)',
        dict(M=0.3702, m=0.0764, l=0.18, **motor(0.1336, 0.2842, 10.6919, 0.0198))),
}

#: per rig, its logs: the repository path (and repository, where not the rig's) with notes and options
LOGS: dict[str, dict[str, dict]] = {
    'utokyo_keisu_cartpend': {
        'lqr_opt111': dict(path='keisu_jikken/touritsu/data/opt111.mat', note='LQR, Q = I, R = 1 (in the file)'),
        'lqr_opt620': dict(path='keisu_jikken/touritsu/data/opt620.0.mat', note='LQR with an observer'),
        'poleplace_1234': dict(path='keisu_jikken/touritsu/data/pole1_2_3_4.mat', note='poles -1 .. -4'),
        'observer_disturbance_shindou': dict(path='keisu_jikken/touritsu/data/paorshindou.mat',
                                             note='pole placement and observer, shaken by hand (shindou)'),
    },
    'uc_enme403_pendulum': {
        'lqr_adm101s1_falls': dict(path='adm101s1.mat', note='the pendulum falls to its stop (90 deg)'),
        'lqr_adm101s2_falls': dict(path='adm101s2.mat', note='the pendulum falls to its stop (90 deg)'),
        **{f'lqr_csm102set{i}_{end}': dict(repo='mcdiarmid/enme403-control-systems-lab',
                                           path=f'Lab-Pendulum/csm102set{i}.mat', note=note)
           for i, end, note in ((1, 'square', 'square reference +/-0.1 m'), (2, 'falls', 'falls after 4 s'),
                                (3, 'square', 'square reference +/-0.1 m'))},
    },
    'uc_enme303_cart': {
        f'app{a}_{f}_P{p}_I{i}_D{d}': dict(path=f'enme303-lab-results/{day}/{f}.mat',
                                           note=f'apparatus {a}, gains P {p}, I {i}, D {d} (the file\'s gain blocks)')
        for a, day, f, p, i, d in (
            (1, 'Mon 22nd', 'acf60_p1', '16p4', 0, 0), (1, 'Mon 22nd', 'acf60_p2', 100, 0, 0),
            (1, 'Mon 22nd', 'acf60_pd1', 105, 0, 10), (1, 'Mon 22nd', 'acf60_pd2', 100, 0, 50),
            (1, 'Mon 22nd', 'acf60_pi1', 75, 200, 0), (1, 'Mon 22nd', 'acf60_pid1', 50, 200, 5),
            (2, 'Mon 22nd', 'acf60p1', 100, 0, 0), (2, 'Mon 22nd', 'acf60pd1', 105, 0, 10),
            (2, 'Mon 22nd', 'acf60pid1', 50, 200, 5), (2, 'Tue 23rd', 'acf60pid', 118, 4, 9),
            (2, 'Tue 23rd', 'acf60pid2', 110, 6, 9), (2, 'Tue 23rd', 'acf60pid3', 110, 6, 5),
            (2, 'Tue 23rd', 'acf60pid4', 115, 6, 7))},
    'uoft_ip02_sip': {
        'sqwave_5p1_outputfb': dict(path='Lab4/ece557-lab4/5.1-better', note='section 5.1: output feedback '
                                    '(observer), square reference +/-0.1 m; only the -better runs saved the input'),
        'sqwave_5p2_integral': dict(path='Lab4/ece557-lab4/5.2-better', note='section 5.2: integral action'),
    },
    'sensorsini_cartpole': {
        'steps_5ms': dict(path='Driver/ExperimentRecordings/5ms Trajectories/CP_PID_2022-01-20_21-44-38 5ms '
                          'measurement short.csv', full_scale=8192, idle_off=True,
                          note='steps of Q (measure.py); the only 5 ms measurement, the repository\'s short file'),
        'steps_20ms': dict(path='Driver/ExperimentRecordings/20ms Trajectories/CP_PID_2022-01-21_18-56-13 20ms '
                           'measurement.csv', full_scale=8192, idle_off=True,
                           note='steps of Q; the whole 142 s file (a 11 s cut of it lies beside it)'),
        'mppi_upright_20ms': dict(path='Driver/ExperimentRecordings/Results/CP_mppi-tf-Euler_2022-02-15_02-41-29 '
                                  'Stabilizing.csv', full_scale=8192, note='MPPI (Euler model) balancing upright'),
        'rpgd_swingup_21ms_2023': dict(path='Driver/ICRA_2023_neural_RPGD_data/ICRA_ODE_2.csv', full_scale=7199,
                                       note='RPGD swing-up (ICRA 2023 data, ODE predictor; ICRA_ODE_3, ICRA_NN '
                                       'and ICRA_NN_2 are its siblings), 7199 counts full scale at b35b20c'),
    },
    'kawata_cdip': {
        'pcont_kP10_logged_v': dict(path='mfiles/p1c3/cdip_least_square_data.mat',
                                    note='P control, kP 10, step 0 -> 0.2 m at 1 s, v logged (the run of '
                                    'cdip_cart_pcont_data_kP_100_ref_02.mat)'),
        **{f'pcont_kP{k}_reconstructed_v': dict(path=f'mfiles/p1c3/cdip_cart_pcont_data_kP_{f}_ref_02.mat', kP=kp,
                                                note=f'P control, kP {kp}, step 0 -> 0.2 m at 1 s, v rebuilt')
           for k, f, kp in (('2p5', '025', 2.5), ('5', '050', 5.0), ('20', '200', 20.0))},
    },
    'aalborg_cart': {
        'square4A_travel_testOffPointFive': dict(path='parameterEstimation/data/cartTest1/testOffPointFive.csv',
                                                 note='+/-4 A square current, the cart travelling the rail'),
        **{f'square4A_at0m{p}': dict(path=f'parameterEstimation/data/cartTest3/0m{p}.csv',
                                     note=f'+/-4 A square current about x = 0.{p} m (cartTest3: the redo after the '
                                     'setup moved, the set run_estimate.m reads)') for p in ('05', '40', '72')},
    },
    'labcontrole_esp32_cartpend': {
        'sine_A150_1Hz_2p5s_reconstructed_v': dict(path='data/raw/dados_16032026_senoide_A150_F1_D2500.csv',
                                                   sine=(150, 1.0, 2.5),
                                                   note='open-loop PWM sine S,150,1,2500; u logged as 0: v rebuilt'),
        'traj_0p1Hz_classicMPC': dict(path='data/raw/Classic/dados_esp32_20260323_Trajetoria_01Hz.csv',
                                      note='classic MPC tracking a 0.1 Hz trajectory'),
        'traj_0p2Hz_classicMPC': dict(path='data/raw/Classic/dados_esp32_20260323_Trajetoria_02Hz.csv',
                                      note='classic MPC tracking a 0.2 Hz trajectory'),
        'disturbance_linearMPC': dict(path='data/raw/Linear/dados_esp32_20260323_Disturbio.csv',
                                      note='linearly parametrised MPC, disturbances by hand'),
        'swingup_expMPC': dict(path='data/raw/Exponencial/dados_esp32_20260323_SwingUp.csv',
                               note='swing-up, then exponentially parametrised MPC'),
        'swingup_mpc_steps_20260317': dict(path='data/raw/dados_17032026_mpc_linear_3.csv', drop_repeats=True,
                                           note='swing-up, then MPC with set-point steps; stamp 53387 ms repeats: '
                                           'its second row (4447) is dropped'),
    },
}


# ------------------------------------------------------------------------------------ reading snapshots
class Snapshot:
    """A repository snapshot under the mirror root; :meth:`read` gives a file of its history."""

    def __init__(self, mirror: Path, repo: str):
        base = mirror / repo.replace('/', '+')
        dirs = [d for d in (base, *base.glob('*'), *base.glob('*/*')) if (d / 'objects').is_dir()]
        if not dirs:
            sys.exit(f'{repo}: no git snapshot under {base} (bring it with the fetch tool: github:{repo})')
        self.repo, self.git = repo, str(dirs[0])
        self.read_log: list[tuple[str, str]] = []    # (path, commit) of each file read

    def _run(self, *args: str) -> bytes:
        return subprocess.run(['git', '--git-dir', self.git, *args], capture_output=True, check=True).stdout

    def read(self, path: str) -> bytes:
        """The file at ``path`` in the newest commit that has it (noted in ``read_log``)."""
        for commit in self._run('rev-list', '--all', '--', path).decode().split():
            if self._run('ls-tree', commit, '--', path).strip():
                self.read_log.append((path, commit))
                return self._run('cat-file', 'blob', f'{commit}:{path}')
        sys.exit(f'{self.repo}: no commit of the snapshot holds {path}')


def loadmat(blob: bytes) -> dict:
    """A MATLAB .mat (or .fig) file's variables, structs as attribute objects."""
    return scipy.io.loadmat(io.BytesIO(blob), squeeze_me=True, struct_as_record=False)


def data_stores(blob: bytes) -> tuple[np.ndarray, dict]:
    """A Simulink "Data Stores" log (one struct: X.Data the time [s], Y the signals): (t, {name: data})."""
    s = next(v for k, v in loadmat(blob).items() if not k.startswith('__'))
    return s.X.Data, {y.Name.split('"')[-2]: np.asarray(y.Data, float) for y in s.Y}


def fig_line(blob: bytes, name: str = '') -> tuple[np.ndarray, np.ndarray]:
    """(XData, YData) of the one line named ``name`` (default: the unnamed one) of a MATLAB .fig file."""
    lines, todo = [], [loadmat(blob)['hgS_070000']]
    while todo:
        node = todo.pop()
        if node.type == 'graph2d.lineseries' and getattr(node.properties, 'DisplayName', '') == name:
            lines.append(node.properties)
        todo += list(np.atleast_1d(node.children)) if np.size(node.children) else []
    (p,) = lines
    return np.asarray(p.XData, float), np.asarray(p.YData, float)


def table(text: str) -> dict[str, list[str]]:
    """The columns of a CSV text with a header row (lines starting with '#' skipped)."""
    rows = list(csv.DictReader(line for line in text.splitlines() if not line.startswith('#')))
    return {k: [r[k] for r in rows] for k in rows[0]}


def num(col: list[str]) -> np.ndarray:
    """A column of :func:`table` as floats."""
    return np.array(col, float)


# ------------------------------------------------------------------------------------ one function per rig
def utokyo_keisu_cartpend(read, log):
    """The lab's Simulink ``data`` struct (data_plot.m): time [s], cart_position [m], pole_angle [rad,
    upright 0: the balancing state], voltage [V] sent to the amplifier (cartpend_*.m plot it so), 2 ms."""
    d = loadmat(read(log['path']))['data']
    return d.time, d.cart_position, d.voltage, d.pole_angle


def uc_enme403_pendulum(read, log):
    """Data Stores CP cart position [m], PPU pendulum angle [rad, upright 0] and RMV raw motor voltage [V]
    (loadPendulumData.m takes them as x, theta, V; read_lab_data.py labels them m, rad, V), 1 ms."""
    t, y = data_stores(read(log['path']))
    return t, y['CP'], y['RMV'], y['PPU']


def uc_enme303_cart(read, log):
    """Data Stores CP [m] and RMV [V] (LabPlotter.m: cart position, motor voltage), 1 ms. RMV is the PID's
    output before the drive: its derivative kicks at each reference step reach 1000 V, where the lab's
    drive gives at most 12 V (the ENME403 logs of the same drives saturate at +/-12 V): clipped there."""
    t, y = data_stores(read(log['path']))
    return t, y['CP'], np.clip(y['RMV'], -12.0, 12.0), None


def uoft_ip02_sip(read, log):
    """The figures lab4_plot.m draws from the Arduino's serial log (T_plot = 30 ms): fig2's line it names
    'Reference Position' is the cart encoder [m] (it labels z_encoder so, z_desired 'Position'), fig3 the
    pendulum angle [rad, upright 0], fig6 the control input [V]."""
    t, x = fig_line(read(log['path'] + '/fig2.fig'), 'Reference Position')
    t3, theta = fig_line(read(log['path'] + '/fig3.fig'))
    t6, v = fig_line(read(log['path'] + '/fig6.fig'), 'Control Input')
    assert np.array_equal(t, t3) and np.array_equal(t, t6), log['path']
    return t, x, v, theta


def sensorsini_cartpole(read, log):
    """The driver's CSV: time [s], position [m], angle [rad, upright 0, wrapped at +/-pi] and
    actualMotorSave, the PWM counts sent (opposite in sign to Q for this motor) of ``full_scale`` counts
    on the 12 V supply: V = 12 (-counts) / full_scale. In a step-response log's idle rows the driver sends
    nothing and the column holds the chip's own number (up to 20436 counts): 0 V there."""
    c = table(read(log['path']).decode())
    v = -12.0 * num(c['actualMotorSave']) / log['full_scale']
    if log.get('idle_off'):
        v[[m.startswith('idle') for m in c['measurement']]] = 0.0
    return num(c['time']), num(c['position']), v, num(c['angle'])


def kawata_cdip(read, log):
    """The book's .mat files: t [s], z [m], theta or phi [rad, 0 hanging: the simulations start from
    theta_0 = pi and plot theta = phi + pi], v [V] in the least-squares file only. Elsewhere v is the P law
    v = kP (zc - z) with zc stepping 0 -> 0.2 m at t = 1 s: on the logged kP = 10 run it gives the logged
    v exactly."""
    d = loadmat(read(log['path']))
    if 'v' in d:
        return d['t'], d['z'], d['v'], d['phi']
    return d['t'], d['z'], log['kP'] * (0.2 * (d['t'] >= 1.0) - d['z']), d['theta']


def aalborg_cart(read, log):
    """Headerless CSV: t [s], current command [A], x [m], x' [m/s] (run_estimate.m: input, cart position,
    velocity; simCart.m turns the input into force by k_tau / r)."""
    a = np.loadtxt(io.BytesIO(read(log['path'])), delimiter=',')
    return a[:, 0], a[:, 2], a[:, 1], None


def labcontrole_esp32_cartpend(read, log):
    """The supervisor's CSV (main_control.cpp's log): t_ms [ms], theta_deg [deg, 0..360, 0 hanging],
    x_cm [cm], u [V] (the law's output, constrained to +/-12 V, sent as PWM u / 12 * 255)."""
    c = table(read(log['path']).decode())
    t, x, u = num(c['t_ms']) / 1000.0, num(c['x_cm']) / 100.0, num(c['u'])
    theta = np.unwrap(np.radians(num(c['theta_deg'])))
    if log.get('drop_repeats'):
        keep = np.r_[True, np.diff(t) > 0]
        t, x, u, theta = t[keep], x[keep], u[keep], theta[keep]
    if 'sine' in log:
        u = esp32_sine(t, x, *log['sine'])
    return t, x, u, theta


def esp32_sine(t, x, amplitude, hz, seconds):
    """The voltage of InvertedPendulumCode.ino's aplicaSenoide (commit 6091289, the log's day): PWM
    int(amplitude |sin 2 pi hz (t - t0)|) of 255 on the 12 V supply, signed as the sine, for ``seconds``.
    Its start t0 is not logged: taken as the stamp before the cart's first move, known to about one 10 ms
    period (the sine passes the declared static friction, 0.38 N, between 10 and 20 ms after its start)."""
    t0 = t[np.flatnonzero(np.diff(x))[0]]
    s = np.sin(2.0 * np.pi * hz * (t - t0))
    on = (t >= t0) & (t < t0 + seconds)
    return np.where(on, np.sign(s) * np.floor(amplitude * np.abs(s)) * 12.0 / 255.0, 0.0)


READERS = {f.__name__: f for f in (utokyo_keisu_cartpend, uc_enme403_pendulum, uc_enme303_cart, uoft_ip02_sip,
                                    sensorsini_cartpole, kawata_cdip, aalborg_cart, labcontrole_esp32_cartpend)}


# ------------------------------------------------------------------------------------ writing
def write_plant(path: Path, rig: str) -> None:
    """Write the rig's ``plant:`` file, its sources as a comment."""
    repo, source, p = PLANTS[rig]
    q = dict(p, g=G)
    vals = ', '.join(f'{k}: {q[k]:.6g}' for k in ('M', 'm', 'l', 'g', 'alpha', 'beta'))
    comment = textwrap.fill(f'{rig}: constants of {repo}, {source}', 100, initial_indent='# ',
                            subsequent_indent='# ')
    path.write_text(f'{comment}\nplant: {{{vals}}}\n')


def write_log(path: Path, t, x, v, theta) -> dict:
    """Write one CSV (t from its first row); its rows, duration and median sample period."""
    t = np.asarray(t, float) - float(t[0])
    cols = [t, x, v] + ([] if theta is None else [theta])
    header = 't,x,voltage' + ('' if theta is None else ',theta')
    np.savetxt(path, np.column_stack(cols), fmt='%.10g', delimiter=',', header=header, comments='')
    return dict(rows=len(t), duration_s=round(float(t[-1]), 3), dt_s=round(float(np.median(np.diff(t))), 6),
                theta=theta is not None)


def unknown_names(only: list[str] | None) -> str | None:
    """Why ``only`` (rig or rig/log names) names no log of :data:`LOGS` (the names that match none, and
    the rigs there are); None when every name matches."""
    known = set(LOGS) | {f'{rig}/{log}' for rig, logs in LOGS.items() for log in logs}
    bad = [n for n in only or [] if n not in known]
    if not bad:
        return None
    return (f'--only: {", ".join(bad)} is no rig or rig/log; rigs: {", ".join(LOGS)} (their logs: the table of '
            'bench/realrigs/convert.py, or manifest.json of a conversion)')


def convert(out: Path, mirror: Path = MIRROR, only: list[str] | None = None) -> list[dict]:
    """Convert every log (or those of ``only``: rig or rig/log names) into ``out``; the manifest rows (with
    ``only``, manifest.json keeps the rows of the other logs already converted there)."""
    rows: list[dict] = []
    snaps: dict[str, Snapshot] = {}
    for rig, logs in LOGS.items():
        picked = [n for n in logs if not only or rig in only or f'{rig}/{n}' in only]
        if not picked:
            continue
        (out / rig).mkdir(parents=True, exist_ok=True)
        write_plant(out / rig / 'plant.yaml', rig)
        for name in picked:
            log = logs[name]
            repo = log.get('repo', PLANTS[rig][0])
            snap = snaps[repo] = snaps.get(repo) or Snapshot(mirror, repo)
            snap.read_log = []
            row = write_log(out / rig / f'{name}.csv', *READERS[rig](snap.read, log))
            rows.append(dict(rig=rig, log=name, repo=repo, paths=[p for p, _ in snap.read_log],
                             commits=sorted({c for _, c in snap.read_log}), note=log['note'], **row))
            print(f'{rig}/{name}: {row["rows"]} rows, {row["duration_s"]} s, dt {row["dt_s"]} s'
                  + ('' if row['theta'] else ', no angle'), flush=True)
    done = {(r['rig'], r['log']) for r in rows}
    kept = json.loads((out / 'manifest.json').read_text()) if only and (out / 'manifest.json').exists() else []
    order = {(rig, log): i for i, (rig, log) in enumerate((rig, log) for rig, logs in LOGS.items() for log in logs)}
    merged = sorted([r for r in kept if (r['rig'], r['log']) not in done] + rows,
                    key=lambda r: order.get((r['rig'], r['log']), len(order)))
    (out / 'manifest.json').write_text(json.dumps(merged, indent=1))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--out', required=True, type=Path, help='output directory (keep it out of the repository)')
    ap.add_argument('--mirror', default=MIRROR, type=Path, help='root of the fetched snapshots (default %(default)s)')
    ap.add_argument('--only', help='comma-separated rig or rig/log names (default: all 42 logs)')
    args = ap.parse_args(argv)
    probe = subprocess.run(['git', 'check-ignore', '-q', str(args.out.resolve() / 'x.csv')], cwd=ROOT,
                           capture_output=True)
    if probe.returncode == 1:        # 0: ignored, 128: outside the repository
        sys.exit(f'{args.out}: in the repository and not ignored by git; these logs must never be committed '
                 '(write them under runs/ or outside the repository)')
    only = args.only.split(',') if args.only else None
    if why := unknown_names(only):
        ap.error(why)
    rows = convert(args.out, args.mirror, only)
    print(f'{len(rows)} logs in {args.out}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
