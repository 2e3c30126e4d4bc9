"""The README's main job: one closed-loop run of a scenario through the ROS 2 nodes, recorded, then
analysed offline; ``OUT/analysis.json`` holds both results (``./ipfric demo``)."""
from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path

from ..analysis.recorded_run import analyze_run
from ..constants import REPO_ROOT
from .runner import Run, RunResult
from .scenario import DEFAULT_SCENARIO

__all__ = ['default_out', 'demo']


def default_out(prefix: str = 'demo') -> Path:
    """A fresh run directory ``runs/<prefix>-<time>`` of the checkout."""
    return REPO_ROOT / 'runs' / time.strftime(f'{prefix}-%Y%m%d-%H%M%S')


def demo(config: str | Path = DEFAULT_SCENARIO, out: str | Path | None = None, duration: float | None = None,
         say: Callable[[str], None] | None = None) -> tuple[RunResult, dict | None]:
    """Run ``config`` (for ``duration`` [s], default the file's) into ``out`` (default :func:`default_out`),
    then analyse its bag (plots in ``out/plots``) and write ``out/analysis.json``; (the run's result, the
    summary {run, analysis}, or None when the run failed). Ctrl-C kills the nodes and re-raises."""
    out = Path(out) if out else default_out()
    r = Run(config, out, duration, timeout=600.0)
    if say:
        say(f'closed-loop run of {config} through the ROS 2 nodes -> {out}')
    r.start()
    try:
        res = r.wait()
    except KeyboardInterrupt:
        r.kill()
        raise
    if res.exit_code != 0:
        return res, None
    summary: dict = {'run': res.to_dict(), 'analysis': analyze_run(out, out / 'plots')}
    (out / 'analysis.json').write_text(json.dumps(summary, indent=2, default=float))
    summary['file'] = str(out / 'analysis.json')
    return res, summary
