"""The layers of ipfric_core, read from every import statement of the source text (function-local
ones included): no layer imports a later one, no module imports a private name of another, no import
cycle anywhere (bench and tests included), and each public name means one thing."""
import ast
import importlib
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CORE = ROOT / 'src' / 'ipfric_core'
PACKAGE = CORE / 'ipfric_core'
#: rank of each layer: a module imports only layers of a lower rank (and its own)
RANK = {'constants': 0, 'lazy': 0, 'physics': 1, 'analysis': 2, 'design': 2, 'run': 3, 'study': 4, 'ident': 5,
        'cli': 6}
LAYERS = ('physics', 'analysis', 'design', 'run', 'study', 'ident')


def module_name(path: Path, base: Path) -> str:
    parts = list(path.relative_to(base).with_suffix('').parts)
    if parts[-1] == '__init__':
        parts = parts[:-1]
    return '.'.join(parts)


def imports(path: Path, base: Path) -> list[tuple[str, list[str]]]:
    """(imported module, imported names) of every import statement of ``path`` (absolute names)."""
    name = module_name(path, base)
    package = name if path.name == '__init__.py' else name.rpartition('.')[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out += [(a.name, []) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parent = package.split('.')[:len(package.split('.')) - node.level + 1]
                mod = '.'.join(parent + ([node.module] if node.module else []))
            else:
                mod = node.module or ''
            out.append((mod, [a.name for a in node.names]))
    return out


def core_modules():
    return sorted(PACKAGE.rglob('*.py'))


def layer_of(module: str) -> str:
    return module.split('.')[1] if module.count('.') else 'package'


@pytest.mark.parametrize('path', core_modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_a_module_imports_only_earlier_layers(path):
    me = module_name(path, CORE)
    if me == 'ipfric_core':
        return
    mine = layer_of(me)
    for mod, names in imports(path, CORE):
        targets = [mod] + [f'{mod}.{n}' for n in names] if mod == 'ipfric_core' else [mod]
        for target in targets:
            if not target.startswith('ipfric_core.'):
                continue
            other = layer_of(target)
            if other == mine or other not in RANK:
                continue
            assert RANK[other] < RANK[mine], f'{me} ({mine}) imports {target} ({other}): a later or sibling layer'


def test_no_private_name_crosses_a_module():
    """``from x import _name`` only within one module's own package file set: never across modules."""
    found = []
    for base, files in ((CORE, core_modules()), (ROOT, list((ROOT / 'bench').rglob('*.py'))),
                        (ROOT, list((ROOT / 'tests').rglob('*.py')))):
        for path in files:
            for mod, names in imports(path, base):
                private = [n for n in names if n.startswith('_') and not n.startswith('__')]
                if private and ('ipfric' in mod or mod.startswith('bench') or mod.startswith('tests')):
                    found.append(f'{path.relative_to(ROOT)} imports {", ".join(private)} from {mod}')
    assert not found, found


def graph() -> dict[str, set[str]]:
    """Module -> modules it imports, over ipfric_core, bench and tests (names as imported)."""
    files = {module_name(p, CORE): p for p in core_modules()}
    files.update({module_name(p, ROOT): p for p in (ROOT / 'bench').rglob('*.py')})
    tests = {module_name(p, ROOT / 'tests'): p for p in (ROOT / 'tests').rglob('*.py')}
    edges: dict[str, set[str]] = {}
    for name, p in list(files.items()) + list(tests.items()):
        base = ROOT / 'tests' if name in tests and p.is_relative_to(ROOT / 'tests') else (
            CORE if p.is_relative_to(CORE) else ROOT)
        known = set(files) | set(tests)
        out = set()
        for mod, names in imports(p, base):
            for target in [f'{mod}.{n}' for n in names] + [mod]:
                if target in known and target != name:
                    out.add(target)
                    break
        edges[name] = out
    return edges


def test_no_import_cycle():
    edges = graph()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    cycles = []
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))
    for v in list(edges):
        if v not in index:
            visit(v)
    # a package's __init__ naming its submodules lazily is not an import
    assert not cycles, cycles


def python(code: str) -> str:
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, cwd=CORE)
    assert out.returncode == 0, out.stderr
    return out.stdout


@pytest.mark.parametrize('layer', LAYERS)
def test_a_public_name_means_one_thing(layer):
    """Every public name of a layer resolves, and none is both a module and a function (the lazy
    lookup would give the function until some import loads the module, then the module)."""
    pkg = importlib.import_module(f'ipfric_core.{layer}')
    modules = {p.stem for p in (PACKAGE / layer).glob('*.py')}
    assert not set(pkg.__all__) & modules
    for name in pkg.__all__:
        assert getattr(pkg, name) is not None


@pytest.mark.parametrize('path', [p for p in core_modules() if p.name not in ('__init__.py', '__main__.py')],
                         ids=lambda p: str(p.relative_to(PACKAGE)))
def test_a_module_says_what_it_offers(path):
    """Each module lists in ``__all__`` the names other modules use; each of them exists."""
    mod = importlib.import_module(module_name(path, CORE))
    assert isinstance(getattr(mod, '__all__', None), list), f'{path.name} has no __all__'
    missing = [n for n in mod.__all__ if not hasattr(mod, n)]
    assert not missing, missing


def test_names_other_modules_use_are_public():
    """What a module imports from another ipfric_core module is in that module's ``__all__``."""
    offered = {}
    for path in core_modules():
        if path.name in ('__init__.py', '__main__.py'):
            continue
        name = module_name(path, CORE)
        tree = ast.parse(path.read_text())
        for node in tree.body:
            if isinstance(node, ast.Assign) and any(getattr(t, 'id', '') == '__all__' for t in node.targets):
                offered[name] = set(ast.literal_eval(node.value))
    bad = []
    for path in core_modules():
        for mod, names in imports(path, CORE):
            if mod in offered:
                bad += [f'{module_name(path, CORE)}: {mod}.{n}' for n in names if n not in offered[mod]]
    assert not bad, bad


def test_the_readme_maps_every_module():
    """The README's module tables list each module of ipfric_core under its layer, and no other."""
    text = (ROOT / 'README.md').read_text()
    modules = {p.relative_to(PACKAGE).as_posix() for p in PACKAGE.rglob('*.py') if p.name != '__init__.py'}
    for layer in LAYERS + ('cli',):
        table = text.split(f'`{layer}/`:', 1)[1].split('\n\n', 2)[1]
        listed = set(re.findall(r'^\| `([a-z_]+\.py)` \|', table, re.M)) - {'__init__.py'}
        assert listed == {m.split('/')[1] for m in modules if m.startswith(f'{layer}/')}, layer
    top = {m for m in modules if '/' not in m}
    assert all(f'| `{m}` |' in text for m in top), top


#: rosdep keys of the Python packages the ROS packages import (the ROS packages are their own keys)
ROSDEP_KEYS = {'numpy': 'python3-numpy', 'scipy': 'python3-scipy', 'yaml': 'python3-yaml', 'numba': 'python3-numba',
               'matplotlib': 'python3-matplotlib', 'zstandard': 'python3-zstandard', 'lz4': 'python3-lz4',
               'control': 'python3-control-pip', 'mcap': 'python3-mcap-pip',
               'mcap_ros2': 'python3-mcap-ros2-support-pip', 'rosbags': 'python3-rosbags-pip'}
#: imports no package.xml declares: the checkout's bench/ (./ipfric bench) and the optional Dask extra
UNDECLARED = {'bench', 'distributed'}


@pytest.mark.parametrize('package', sorted(p.name for p in (ROOT / 'src').iterdir() if (p / 'package.xml').exists()))
def test_every_package_declares_what_it_imports(package):
    """rosdep install of a package brings every module its code imports (numba, mcap, rosbags, ...)."""
    import xml.etree.ElementTree as ET
    src = ROOT / 'src' / package
    imported = set()
    for f in src.rglob('*.py'):
        if f.name == 'setup.py':
            continue
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.Import):
                imported |= {a.name.split('.')[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                imported.add(node.module.split('.')[0])
    imported -= set(sys.stdlib_module_names) | {'__future__', package} | UNDECLARED
    declared = {e.text for e in ET.parse(src / 'package.xml').getroot()
                if e.tag in ('depend', 'exec_depend', 'build_export_depend')}
    missing = sorted(ROSDEP_KEYS.get(m, m) for m in imported if ROSDEP_KEYS.get(m, m) not in declared)
    assert not missing, f'{package}/package.xml does not declare {missing}'


def test_every_safety_event_code_has_its_constant():
    """SafetyEvent.msg has a constant for each code sim_node publishes, and none it never publishes."""
    from ipfric_core.constants import EVENT_CODES
    msg = (ROOT / 'src' / 'ipfric_msgs' / 'msg' / 'SafetyEvent.msg').read_text()
    assert sorted(re.findall(r'^string ([A-Z_]+)="\1"$', msg, re.M)) == sorted(EVENT_CODES)
    sim = '\n'.join(p.read_text() for p in (ROOT / 'src' / 'ipfric_sim' / 'ipfric_sim').glob('*.py'))
    used = set(re.findall(r'SafetyEvent\.([A-Z_]+)', sim)) | set(re.findall(r"^([A-Z_]+) = '\1'$", sim, re.M))
    assert used <= set(EVENT_CODES) and {'STALL', 'INTRUDER', 'BAD_COMMAND', 'WATCHDOG'} <= used


@pytest.mark.ros
@pytest.mark.parametrize('module', ['ipfric_sim.sim_node', 'ipfric_controller.controller_node',
                                    'ipfric_record.recorder'])
def test_the_nodes_start_without_the_slow_imports(module):
    """Each ROS node imports what it runs; python-control, scipy.signal and matplotlib.pyplot (seconds of
    import, paid by each of a run's three nodes: a 12 s lockstep run took 27 s of wall time with them,
    19 s without) come with the function that uses them (the LQR design of a controller that designs its
    gain)."""
    slow = ('control', 'scipy.signal', 'matplotlib.pyplot')
    code = f'import sys, {module}; print([m for m in {slow!r} if m in sys.modules])'
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == '[]', out.stdout
