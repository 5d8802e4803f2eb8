"""Optional dependencies, imported where they are used: a missing one is an ImportError whose
message names what needs it and the pip install that brings it (the CLI prints that one line)."""
from __future__ import annotations

import importlib
from types import ModuleType


class MissingDependencyError(ImportError):
    """An optional package is not installed; the message says which install brings it."""


def require(module: str, needed_for: str, install: str) -> ModuleType:
    """import `module`, or raise MissingDependencyError naming `needed_for` and `install`."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingDependencyError(f"{needed_for} needs {install.split()[-1]} "
                                     f"(pip install {install}): {exc}") from None
