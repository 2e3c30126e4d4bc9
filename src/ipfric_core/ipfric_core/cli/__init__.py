"""Command line of ipfric: ``./ipfric <command> [--json]``, one module per command.

Each command module has ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``main(args) -> int``:
it parses, calls the layers and prints (text, or the result as JSON with ``--json``).
A :class:`~ipfric_core.physics.params.ConfigError` or an unreachable scheduler ends the
command with its message and exit code 2.
"""
from __future__ import annotations

import argparse
import sys

from ..physics.params import ConfigError
from ..study.executor import SchedulerError
from . import analyze, bench, demo, design, identify, montecarlo, orbit, run, stability, sweep

__all__ = ['COMMANDS', 'build_parser', 'main']

#: the commands in the order ``--help`` lists them
COMMANDS = (design, stability, demo, run, analyze, sweep, montecarlo, identify, orbit, bench)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog='ipfric', description='Friction and the inverted pendulum: '
                                'design, simulation, ROS 2 closed loop and analysis.')
    sub = p.add_subparsers(dest='command', required=True, metavar='command')
    for cmd in COMMANDS:
        sp = sub.add_parser(cmd.NAME, help=cmd.HELP, description=cmd.HELP)
        sp.add_argument('--json', action='store_true', help='print a machine-readable result on stdout')
        cmd.add_arguments(sp)
        sp.set_defaults(func=cmd.main)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except ConfigError as exc:
        print(f'ipfric {args.command}: configuration error: {exc}', file=sys.stderr)
        return 2
    except SchedulerError as exc:
        print(f'ipfric {args.command}: {exc}', file=sys.stderr)
        return 2
