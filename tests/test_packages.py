"""The layer subpackages: each public name means one thing, and no layer imports a later one."""
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

CORE = Path(__file__).resolve().parents[1] / 'src' / 'ipfric_core'
LAYERS = ('physics', 'design', 'run', 'analysis', 'ident')   # each imports only those before it


def python(code: str) -> str:
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, cwd=CORE)
    assert out.returncode == 0, out.stderr
    return out.stdout


@pytest.mark.parametrize('layer', LAYERS)
def test_a_module_name_means_the_module(layer):
    """A package name that were both a module and a function would give the function until some
    import loads the module, then the module: the lazy lookup must give the module too."""
    other = python(f'''
import importlib, pkgutil
import ipfric_core.{layer} as pkg
names = [m.name for m in pkgutil.iter_modules(pkg.__path__)]
print(sorted(n for n in names if pkg.__getattr__(n) is not importlib.import_module(f'{{pkg.__name__}}.{{n}}')))
''')
    assert other.strip() == '[]'


@pytest.mark.parametrize('layer', LAYERS[:-1])
def test_a_layer_imports_no_later_layer(layer):
    later = LAYERS[LAYERS.index(layer) + 1:]
    loaded = python(f'''
import importlib, json, pkgutil, sys
import ipfric_core.{layer} as pkg
for m in pkgutil.iter_modules(pkg.__path__):
    importlib.import_module(f'{{pkg.__name__}}.{{m.name}}')
print(json.dumps(sorted({{n.split('.')[1] for n in sys.modules if n.startswith('ipfric_core.')}})))
''')
    assert not set(json.loads(loaded)) & set(later), loaded


def test_the_readme_maps_every_module():
    """The README's module tables list each module of ipfric_core under its layer, and no other."""
    text = (CORE.parents[1] / 'README.md').read_text()
    package = CORE / 'ipfric_core'
    modules = {p.relative_to(package).as_posix() for p in package.rglob('*.py') if p.name != '__init__.py'}
    for layer in LAYERS:
        table = text.split(f'`{layer}/`:', 1)[1].split('\n\n', 2)[1]
        listed = set(re.findall(r'^\| `([a-z_]+\.py)` \|', table, re.M))
        assert listed == {m.split('/')[1] for m in modules if m.startswith(f'{layer}/')}, layer
    top = {m for m in modules if '/' not in m}
    assert all(f'| `{m}` |' in text for m in top), top
