"""``./ipfric run``: one closed-loop run of the ROS 2 nodes, recorded to a rosbag2 MCAP.

Starts three processes in a fresh ROS domain with DDS kept on loopback
(``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``): the recorder, the controller and the
simulator, each from ``ros2_ws/install/<pkg>/lib/<pkg>/`` with
``--ros-args --params-file <OUT>/scenario.yaml``. Nothing waits a fixed time: the
controller announces itself (latched ``controller_gain``) once its command publisher is
matched by the simulator and the recorder, and the simulator starts sample 0 only when
that message arrived and the recorder subscribes to each of its topics.

The run ends when the simulator exits (duration reached, a limit crossed, or stopped);
then the controller and the recorder are stopped with SIGINT, in that order, so that the
recorder takes every queued message and closes the bag. Ctrl-C, SIGTERM and SIGHUP do the
same. The nodes die with the runner however it dies (``kill -9`` included): the kernel
sends them SIGTERM (``PR_SET_PDEATHSIG``) and their stdin pipe closes; the recorder then
closes the bag. A node that dies ends the run with exit code 1 and a message naming it
once; the bag recorded up to that moment stays readable, and a bag the recorder could not
close is read back as ``analyze`` reads it, its loss stated.

Exit codes: 0 clean; 1 a node failed; 2 bad input (nothing started); 3 a safety fault
(watchdog, stalled controller, refused commands, unexpected publisher); 4 the pendulum
fell or the cart reached the track limit; 130 stopped by Ctrl-C/SIGTERM/SIGHUP.

Output directory ``OUT``: ``bag/`` (metadata.yaml + bag_0.mcap), ``scenario.yaml`` (the
parameter file the nodes got, duration applied), ``sim_result.json`` (end reason, samples,
published counts, speed), ``summary.json`` and ``logs/<node>.log``.

This module starts processes only; it imports no ROS package.
"""
from __future__ import annotations

import ctypes
import fcntl
import json
import math
import os
import random
import signal
import socket
import subprocess
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import yaml

from ..constants import LIMITS, REPO_ROOT
from ..physics.params import ConfigError
from .nodes import NODES, node_parameters, ros_args, write_run_scenario
from .scenario import check_namespace

__all__ = ['EXIT_FELL', 'EXIT_FAULT', 'SUPERVISED', 'DomainLock', 'die_with_parent', 'ros_environment', 'domain_in_use',
           'pick_domain', 'claim_domain', 'executable', 'RunResult', 'Run', 'run']

#: Exit codes of a run besides 0, 1 (a node failed), 2 (bad input) and 130 (Ctrl-C).
EXIT_FAULT = 3    # a safety fault: watchdog, stall, refused commands, unexpected publisher
EXIT_FELL = 4     # the pendulum fell or the cart reached the track limit (otherwise clean)
#: The ROS_DOMAIN_IDs a run accepts (Fast DDS on Linux: ports 7400 + 250 * domain + ... stay below 65536).
DOMAINS = (0, 232)


# ---------------------------------------------------------------------------- environment
PR_SET_PDEATHSIG = 1          # linux/prctl.h
#: Environment variable telling a node that a supervisor watches it (ipfric_ros.signals).
SUPERVISED = 'IPFRIC_SUPERVISED'


def die_with_parent(sig: int = signal.SIGTERM) -> None:
    """Ask the kernel to send ``sig`` to this process when its parent exits (Linux prctl)."""
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), 'prctl(PR_SET_PDEATHSIG) failed')


def ros_environment(domain: int) -> dict:
    """The environment of scripts/env.sh plus the run's domain, DDS on loopback only."""
    env_sh = REPO_ROOT / 'scripts' / 'env.sh'
    out = subprocess.run(['bash', '-c', f'set -e; source "{env_sh}" >/dev/null; env -0'],
                         capture_output=True, check=True)
    env = dict(item.split('=', 1) for item in out.stdout.decode().split('\0') if '=' in item)
    env.update(ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               RCUTILS_COLORIZED_OUTPUT='0', PYTHONUNBUFFERED='1')
    return env


#: Participants of one domain whose discovery port is probed (Fast DDS fits 120 in a domain's 250 ports).
PARTICIPANTS = 120
#: Where the runs of this machine hold their domain (and namespace) locks.
LOCKS = Path(tempfile.gettempdir()) / 'ipfric-ros-domains'


def domain_in_use(domain: int) -> bool:
    """True when any participant's unicast discovery port of ``domain`` is taken.

    Fast DDS: port = 7400 + 250 * domain + 10 + 2 * participant (a participant takes the first
    free one, so the one of participant 0 may be free while later ones still run).
    """
    for participant in range(PARTICIPANTS):
        port = 7400 + 250 * domain + 10 + 2 * participant
        if port > 65535:            # the last domains hold fewer participants
            break
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            try:
                s.bind(('0.0.0.0', port))
            except OSError:
                return True
    return False


class DomainLock:
    """A ROS domain held by one run of this machine, from the check that it is free to the run's end.

    A run at the root namespace holds its domain alone (an exclusive ``flock``); a run in a
    namespace shares the domain with runs in other namespaces (a shared lock) and holds its
    namespace alone. The locks go with the process however it ends, so a killed run frees them.
    """

    def __init__(self, domain: int, namespace: str = '/'):
        self.domain, self.namespace = domain, namespace
        self.files: list = []

    def _take(self, name: str, exclusive: bool) -> bool:
        LOCKS.mkdir(parents=True, exist_ok=True)
        f = open(LOCKS / name, 'a')
        try:
            fcntl.flock(f, (fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH) | fcntl.LOCK_NB)
        except OSError:
            f.close()
            return False
        self.files.append(f)
        return True

    def acquire(self) -> str | None:
        """Take the locks; None, or why the domain (or namespace) is not free."""
        shared = self.namespace != '/'
        if not self._take(f'domain-{self.domain}', exclusive=not shared):
            return (f'ROS domain {self.domain} is in use by another ./ipfric run'
                    + (' at the root namespace' if shared else ''))
        if shared and not self._take(f'domain-{self.domain}{self.namespace.replace("/", "-")}', exclusive=True):
            self.release()
            return f'namespace {self.namespace} of ROS domain {self.domain} is in use by another ./ipfric run'
        return None

    def release(self) -> None:
        for f in self.files:
            f.close()
        self.files = []


def pick_domain(rng: random.Random | None = None) -> int:
    """A ROS_DOMAIN_ID in 1..232 that no participant on this machine uses (not held: see :func:`claim_domain`)."""
    rng = rng or random.Random(os.getpid() ^ time.monotonic_ns())
    candidates = list(range(max(1, DOMAINS[0]), DOMAINS[1] + 1))
    rng.shuffle(candidates)
    for d in candidates:
        if not domain_in_use(d):
            return d
    raise RuntimeError('no free ROS domain id in 1..232')


def claim_domain(domain: int | None = None, namespace: str = '/') -> DomainLock:
    """The domain of a run, held until :meth:`DomainLock.release` (or the process's end).

    ``domain`` None: a free one (no participant, no other run's lock), taken atomically, so two
    runs started at once never pick the same. A given domain is refused (ConfigError) when another
    ./ipfric run holds it, or, at the root namespace, when any participant uses it; a run in a
    namespace may share a domain with other rigs (each in its namespace) but not its namespace.
    """
    if domain is None:
        rng = random.Random(os.getpid() ^ time.monotonic_ns())
        candidates = list(range(max(1, DOMAINS[0]), DOMAINS[1] + 1))
        rng.shuffle(candidates)
        for d in candidates:
            if domain_in_use(d):
                continue
            lock = DomainLock(d)
            if lock.acquire() is None:
                if not domain_in_use(d):
                    return lock
                lock.release()
        raise RuntimeError('no free ROS domain id in 1..232')
    if not DOMAINS[0] <= domain <= DOMAINS[1]:
        raise ConfigError(f'--domain: {domain} is out of range; allowed {DOMAINS[0]}..{DOMAINS[1]}')
    lock = DomainLock(domain, namespace)
    why = lock.acquire()
    if why is None and namespace == '/' and domain_in_use(domain):
        lock.release()
        why = f'ROS domain {domain} is in use by another process on this machine'
    if why:
        raise ConfigError(f'--domain: {why}; give another, leave --domain out (a free one is picked)'
                          + ('' if namespace != '/' else ', or run in a --namespace of its own'))
    return lock


def executable(name: str) -> Path:
    pkg, exe = NODES[name]
    path = REPO_ROOT / 'ros2_ws' / 'install' / pkg / 'lib' / pkg / exe
    if not path.exists():
        raise FileNotFoundError(f'{path} not found: build the workspace (bash scripts/setup.sh)')
    return path


def describe_exit(code: int | None) -> str:
    if code is None:
        return 'still running'
    if code < 0:
        try:
            return f'killed by {signal.Signals(-code).name}'
        except ValueError:
            return f'killed by signal {-code}'
    return f'exit code {code}'


def last_problem(log: Path) -> str:
    """The last FATAL/ERROR line (or traceback line, or the signal that stopped it) of a node log,
    for the message."""
    try:
        lines = log.read_text(errors='replace').splitlines()
    except OSError:
        return ''
    for line in reversed(lines):
        if '[FATAL]' in line or '[ERROR]' in line or 'Error' in line or 'stopped by SIG' in line:
            return line.strip()
    return ''


# ---------------------------------------------------------------------------- the run
@dataclass
class RunResult:
    exit_code: int
    end_reason: str | None
    detail: str | None
    out: str
    bag: str
    domain: int | None
    samples: int | None = None
    sim_time_s: float | None = None
    wall_time_s: float | None = None
    steps_per_s: float | None = None
    published: dict = field(default_factory=dict)
    recorded: dict = field(default_factory=dict)
    counts_match: bool | None = None
    failures: list = field(default_factory=list)
    faults: list = field(default_factory=list)
    interrupted: bool = False
    exit_codes: dict = field(default_factory=dict)
    bag_loss: list = field(default_factory=list)
    namespace: str = '/'

    def to_dict(self) -> dict:
        return asdict(self)

    def summary(self) -> str:
        lines = []
        if self.end_reason:
            lines.append(f'run: {self.end_reason} ({self.detail}) after {self.samples} samples '
                         f'({self.sim_time_s:.3f} s simulated) in {self.wall_time_s:.1f} s wall '
                         f'({self.steps_per_s:.0f} samples/s), ROS domain {self.domain}'
                         + ('' if self.namespace == '/' else f', namespace {self.namespace}'))
        else:
            lines.append(f'run: no end reason (the simulator did not finish), ROS domain {self.domain}')
        if self.recorded:
            lines.append(f'bag: {self.bag} (rosbag2, MCAP{", NOT CLOSED" if self.bag_loss else ""}), '
                         + ', '.join(f'{t} {n}' for t, n in self.recorded.items()))
        else:
            lines.append(f'bag: {self.bag}: not readable')
        for loss in self.bag_loss:
            lines.append(f'bag loss: {loss}')
        if self.counts_match is not None:
            lines.append('recorded == published by sim_node: ' + ('yes' if self.counts_match else 'NO'))
        for f in self.failures:
            lines.append(f'FAILED: {f}')
        for f in self.faults:
            lines.append(f'FAULT: {f}')
        if self.interrupted:
            lines.append('interrupted (Ctrl-C): all nodes stopped')
        lines.append(f'logs: {Path(self.out) / "logs"}')
        return '\n'.join(lines)


class Run:
    """One run: :meth:`start`, then :meth:`wait` (or use :func:`run`).

    Parameters
    ----------
    config : scenario parameter file (sim_node / controller_node sections), or an installed scenario's name
    out : output directory (created; must not hold a bag yet)
    duration : simulated seconds, overriding the file's sim_node duration (None = keep)
    domain : ROS_DOMAIN_ID (None = a free one)
    namespace : the rig's ROS namespace (``/rig1``; None = the root); with a given ``domain``,
        rigs in different namespaces share it
    time_mode : lockstep | realtime, overriding the file's (None = keep)
    node_params : node name -> parameters set on top of what the run gives it (e.g. the loop tuning
        of :mod:`ipfric_ros.realtime` to compare settings)
    timeout : wall seconds after which the simulator is stopped (None = none)
    grace : wall seconds the simulator may run on after the controller died (its
        watchdog acts) before it is stopped
    stop_wait : wall seconds the simulator has to end after SIGINT before it is killed
    """

    def __init__(self, config, out, duration: float | None = None, domain: int | None = None,
                 timeout: float | None = None, grace: float = 20.0, node_params: dict | None = None,
                 stop_wait: float = 20.0, namespace: str | None = None, time_mode: str | None = None):
        self.config = config
        self.out = Path(out).resolve()  # the nodes run with cwd = out
        self.duration = duration
        self.domain = domain
        self.namespace = namespace
        self.time_mode = time_mode
        self.lock: DomainLock | None = None
        self.scenario: Path | None = None     # OUT/scenario.yaml, once prepared
        self.signalled_sim = False      # the runner asked the simulator to stop
        self.timeout = timeout
        self.grace = grace
        self.stop_wait = stop_wait
        self.node_params = {name: dict(p) for name, p in (node_params or {}).items()}
        self.procs: dict[str, subprocess.Popen] = {}
        self.logs: dict[str, Path] = {}
        self.failures: list[str] = []
        self.interrupted = False
        self._files: list = []

    # -- start -----------------------------------------------------------------------------
    def prepare(self) -> Path:
        """Validate the arguments and the scenario, hold the run's ROS domain, then write
        OUT/scenario.yaml (raises ConfigError, nothing written and no domain held). :meth:`start`
        prepares a run not prepared yet."""
        self.namespace = check_namespace(self.namespace)
        if self.timeout is not None and not (math.isfinite(self.timeout) and self.timeout > 0):
            raise ConfigError(f'--timeout: {self.timeout!r} must be > 0 wall seconds')
        if self.out.exists() and not self.out.is_dir():
            raise ConfigError(f'--out: {self.out} is a file; give a directory (created if missing)')
        if (self.out / 'bag').exists():
            raise ConfigError(f'{self.out / "bag"} exists already; choose another --out')
        if self.duration is not None and not (math.isfinite(self.duration) and self.duration >= 0):
            raise ConfigError(f'--duration: {self.duration!r} must be >= 0 s')
        overrides: dict = {} if self.duration is None else {'duration': float(self.duration)}
        if self.time_mode is not None:
            overrides['time_mode'] = self.time_mode
        self.lock = claim_domain(self.domain, self.namespace)
        self.domain = self.lock.domain
        try:
            self.scenario = write_run_scenario(self.config, self.out, overrides, self.namespace)
        except BaseException:
            self.lock.release()
            raise
        return self.scenario

    def start(self) -> None:
        cfg = self.scenario or self.prepare()
        assert self.lock is not None and self.namespace is not None
        env = ros_environment(self.lock.domain)
        logdir = self.out / 'logs'
        logdir.mkdir(exist_ok=True)
        env['ROS_LOG_DIR'] = str(logdir / 'ros')
        env[SUPERVISED] = '1'
        params = node_parameters(cfg, self.out)
        for name, extra in self.node_params.items():
            params[name][1].update(extra)
        args = {name: ros_args(params[name][0], params[name][1], self.namespace) for name in NODES}
        self.t0 = time.monotonic()
        for name in NODES:
            exe = executable(name)
            self.logs[name] = logdir / f'{name}.log'
            f = open(self.logs[name], 'w')
            self._files.append(f)
            # a node dies with the runner: SIGTERM from the kernel, and the end of its stdin pipe
            # (the recorder, by the pipe alone, a little later: ipfric_ros.signals)
            self.procs[name] = subprocess.Popen([str(exe), '--ros-args', *args[name]], env=env, cwd=self.out,
                                                stdout=f, stderr=subprocess.STDOUT, stdin=subprocess.PIPE,
                                                start_new_session=True,
                                                preexec_fn=None if name == 'recorder' else die_with_parent)

    def kill(self) -> None:
        """SIGKILL every process still running (last resort, e.g. a failed test)."""
        for name, p in self.procs.items():
            if p.poll() is None:
                self._signal(name, signal.SIGKILL)
                p.wait()

    # -- supervision -----------------------------------------------------------------------
    def _died(self, name: str) -> str:
        p = self.procs[name]
        why = last_problem(self.logs[name])
        return f'{name} {describe_exit(p.returncode)} ({self.logs[name]})' + (f': {why}' if why else '')

    def _signal(self, name: str, sig=signal.SIGINT) -> None:
        p = self.procs.get(name)
        if p is not None and p.poll() is None:
            try:
                p.send_signal(sig)
            except ProcessLookupError:
                pass

    def _stop(self, name: str, wait: float) -> None:
        """SIGINT, then SIGTERM, then SIGKILL, each after ``wait`` s."""
        p = self.procs[name]
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
            if p.poll() is not None:
                return
            self._signal(name, sig)
            try:
                p.wait(timeout=wait)
                return
            except subprocess.TimeoutExpired:
                if sig == signal.SIGKILL:
                    raise

    def supervise(self) -> None:
        """Return once the simulator exited (stopping it on timeout, Ctrl-C or a dead peer)."""
        sim = self.procs['sim_node']
        stop_at = None
        signalled = None    # when the simulator was asked to stop
        reported = set()
        while sim.poll() is None:
            try:
                time.sleep(0.05)
            except KeyboardInterrupt:
                self.interrupted = True
                stop_at = time.monotonic()
            now = time.monotonic()
            if signalled is not None:
                if now - signalled > self.stop_wait:
                    self.failures.append(f'sim_node did not stop within {self.stop_wait:g} s of SIGINT; killed')
                    self._stop('sim_node', 5.0)
                continue
            for name in ('recorder', 'controller_node'):
                if name not in reported and self.procs[name].poll() is not None:
                    reported.add(name)
                    self.failures.append(self._died(name) + ' before the run ended')
                    # the recorder gone: nothing is kept any more, stop now; the controller
                    # gone: the simulator's watchdog acts, let it finish for a while
                    delay = 0.0 if name == 'recorder' else self.grace
                    stop_at = min(stop_at or math.inf, now + delay)
            if self.timeout is not None and now - self.t0 > self.timeout and 'timeout' not in reported:
                reported.add('timeout')
                self.failures.append(f'sim_node still running after the {self.timeout:g} s timeout; stopped')
                stop_at = now
            if stop_at is not None and now >= stop_at:
                self._signal('sim_node')
                signalled = now
                self.signalled_sim = True
        if sim.returncode != 0 and not (signalled is not None and self.failures):
            # (a simulator stopped by the runner after a named failure is not a second failure)
            self.failures.append(self._died('sim_node'))

    def wait(self) -> RunResult:
        try:
            self.supervise()
            for name, wait in (('sim_node', 20.0), ('controller_node', 10.0), ('recorder', 30.0)):
                alive = self.procs[name].poll() is None
                self._stop(name, wait)
                code = self.procs[name].returncode
                if alive and code != 0 and name != 'sim_node':
                    self.failures.append(f'{name} did not stop cleanly: {self._died(name)}')
        except KeyboardInterrupt:  # a second Ctrl-C: no more patience
            self.interrupted = True
            self.kill()
            self.failures.append('stopped hard by a second Ctrl-C; the bag may be incomplete')
        finally:
            for f in self._files:
                f.close()
            for p in self.procs.values():
                if p.stdin:
                    p.stdin.close()
            if self.lock is not None:
                self.lock.release()
        return self.result()

    # -- result ----------------------------------------------------------------------------
    def result(self) -> RunResult:
        sim = {}
        try:
            sim = json.loads((self.out / 'sim_result.json').read_text())
        except (OSError, ValueError):
            pass
        recorded, loss = self.recorded()
        published = sim.get('published', {})
        if sim.get('stopped_by') and not self.signalled_sim and not self.interrupted:
            self.failures.append(f'sim_node was stopped by {sim["stopped_by"]} from outside ./ipfric run after '
                                 f'{sim.get("samples")} samples ({sim.get("sim_time_s", 0):.3f} s simulated): '
                                 f'the run did not end by itself')
        match = None
        if published and recorded:
            got = {t: recorded.get(t, 0) for t in published}
            intruded = set(sim.get('intruders', {}))
            # more than published on a topic another writer used: its messages, reported as INTRUDER
            bad = {t: n for t, n in published.items() if got[t] < n or (got[t] > n and t not in intruded)}
            match = not bad
            if bad:
                lost = ', '.join(f'{t} {got[t]} of {n}' for t, n in bad.items())
                # a bag the recorder did not close: its loss, already a named failure of the recorder
                (loss if loss else self.failures).append(f'recorded of the messages published: {lost}')
        faults = sim_faults(sim)
        code = 0
        if self.failures:
            code = 1
        elif faults:
            code = EXIT_FAULT
        elif self.interrupted:
            code = 130
        elif sim.get('end_reason') in LIMITS:
            code = EXIT_FELL
        res = RunResult(exit_code=code, end_reason=sim.get('end_reason'), detail=sim.get('detail'),
                        out=str(self.out), bag=str(self.out / 'bag'), domain=self.domain,
                        samples=sim.get('samples'), sim_time_s=sim.get('sim_time_s'),
                        wall_time_s=sim.get('wall_time_s'), steps_per_s=sim.get('steps_per_s'),
                        published=published, recorded=recorded, counts_match=match,
                        failures=list(self.failures), faults=faults, interrupted=self.interrupted,
                        exit_codes={n: p.returncode for n, p in self.procs.items()}, bag_loss=loss,
                        namespace=self.namespace or '/')
        (self.out / 'summary.json').write_text(json.dumps(res.to_dict(), indent=2))
        return res


    def recorded(self) -> tuple[dict, list]:
        """Messages per topic in the bag, and what was lost: from metadata.yaml (the recorder
        closed the bag), else read from the .mcap itself as ``analyze`` reads it."""
        try:
            meta = yaml.safe_load((self.out / 'bag' / 'metadata.yaml').read_text())
            return {t['topic_metadata']['name']: t['message_count']
                    for t in meta['rosbag2_bagfile_information']['topics_with_message_count']}, []
        except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError):
            pass
        from ..analysis.bagread import read_run
        try:
            bag = read_run(self.out / 'bag')
        except ConfigError as exc:
            return {}, [str(exc)]
        return bag.counts, [f'not closed by the recorder: {bag.truncation_detail}'] * bag.truncated + bag.damage


def sim_faults(sim: dict) -> list[str]:
    """The safety faults a simulator result reports: watchdog, stalls, refused commands, intruders."""
    out = []
    if sim.get('stalls'):
        out.append(f'the controller stalled {sim["stalls"]} time(s) (no command for a second of wall time)')
    if sim.get('watchdog_trips'):
        out.append(f'the watchdog tripped {sim["watchdog_trips"]} time(s) (0 V applied)')
    if sim.get('commands_refused'):
        kinds = ', '.join(f'{n} {k}' for k, n in sorted(sim.get('refused_by_kind', {}).items()))
        out.append(f'{sim["commands_refused"]} command(s) refused ({kinds})')
    for topic, nodes in sorted(sim.get('intruders', {}).items()):
        out.append(f'{len(nodes)} unexpected publisher(s) on {topic}: {", ".join(nodes)}')
    return out


def run(config, out, duration: float | None = None, **kwargs) -> RunResult:
    """Start, supervise and stop one run; see :class:`Run`."""
    r = Run(config, out, duration, **kwargs)
    r.start()
    return r.wait()
