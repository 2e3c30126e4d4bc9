"""Lazy public names of a package: each is imported from its module on first use."""
from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable

__all__ = ['lazy_package']


def lazy_package(package: str, path, public: dict[str, tuple[str, ...]]) -> tuple[list[str], Callable[[str], object]]:
    """(``__all__``, module ``__getattr__`` (PEP 562)) of ``package`` (at ``path``): a name of ``public``
    (module -> its names a user calls) comes from that module, a submodule's name is the submodule."""
    where = {name: module for module, names in public.items() for name in names}
    modules = {m.name for m in pkgutil.iter_modules(path)}

    def __getattr__(name: str):
        if name in where:
            return getattr(importlib.import_module(f'.{where[name]}', package), name)
        if name in modules:
            return importlib.import_module(f'.{name}', package)
        raise AttributeError(f'module {package!r} has no attribute {name!r}')
    return sorted(where), __getattr__
