"""Packages whose public names are imported on first use (PEP 562), so that a command loads only
what it runs: ``rrtpso --version`` no numpy, ``rrtpso optimum`` no OMPL, nothing matplotlib
unless a picture is drawn (docs/design.md, "Start-up").

A package's ``__init__`` declares where each public name lives and calls :func:`export_lazily`::

    __all__ = ["World", "load_problem"]
    export_lazily(__name__, {"World": ".world", "load_problem": ".problem"})

``from package import World``, ``package.World`` and ``from package import *`` then work as if
``__init__`` had imported them, and importing ``package`` costs nothing more. A name that is
also the name of the submodule defining it (``groundtruth.generate``, the function of
``groundtruth/generate.py``) stays the function: importing the submodule, which makes Python
bind the submodule on its package, does not replace it (as an eager ``from .generate import
generate`` in ``__init__`` behaved).
"""

from __future__ import annotations

import importlib
import sys
import types
from collections.abc import Mapping
from typing import Any

__all__ = ["LazyPackage", "export_lazily"]


class LazyPackage(types.ModuleType):
    """The class of a package made lazy by :func:`export_lazily` (Python's documented way to
    customise a module's attributes: setting its ``__class__``)."""

    _lazy_exports: Mapping[str, str]

    def __getattr__(self, name: str) -> Any:
        # Called only when the name is not (yet) an attribute of the package.
        where = self.__dict__.get("_lazy_exports", {}).get(name)
        if where is None:
            raise AttributeError(f"module {self.__name__!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(where, self.__name__), name)
        setattr(self, name, value)  # once: the next access is an ordinary attribute
        return value

    def __setattr__(self, name: str, value: Any) -> None:
        if (
            isinstance(value, types.ModuleType)
            and value.__name__ == f"{self.__name__}.{name}"
            and self.__dict__.get("_lazy_exports", {}).get(name) == f".{name}"
        ):
            # Python binds a submodule on its package once it is imported; the package exports
            # the submodule's function of the same name instead (see the module docstring).
            value = getattr(value, name)
        super().__setattr__(name, value)

    def __dir__(self) -> list[str]:
        return sorted(set(super().__dir__()) | set(self.__dict__.get("_lazy_exports", {})))


def export_lazily(package: str, exports: Mapping[str, str]) -> None:
    """Make the names of ``exports`` attributes of ``package``, each imported on first access.

    Parameters
    ----------
    package : str
        The package's ``__name__`` (call this from its ``__init__``).
    exports : mapping of str to str
        Public name -> the module defining it, relative to ``package`` (``".world"``) or absolute.
    """
    module = sys.modules[package]
    module.__class__ = LazyPackage
    module._lazy_exports = dict(exports)
