"""Lazy public names of a package: each is imported from its module on first use."""
from __future__ import annotations

import importlib
from collections.abc import Callable

__all__ = ['lazy_getattr']


def lazy_getattr(package: str, where: dict[str, str], modules: list[str]) -> Callable[[str], object]:
    """A module ``__getattr__`` (PEP 562) for ``package``: a name of ``where`` (name -> module)
    comes from that module, a name of ``modules`` is the submodule itself."""
    def __getattr__(name: str):
        if name in where:
            return getattr(importlib.import_module(f'.{where[name]}', package), name)
        if name in modules:
            return importlib.import_module(f'.{name}', package)
        raise AttributeError(f'module {package!r} has no attribute {name!r}')
    return __getattr__
