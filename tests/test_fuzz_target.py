"""fuzz/fuzz_decoders.py needs atheris, which the tests do not install: what it imports
from appmode must still be there (it once named decoders that had moved)."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

from tests.support.source import parsed

TARGET = Path(__file__).parent.parent / "fuzz" / "fuzz_decoders.py"


def test_the_fuzz_target_imports_what_appmode_has() -> None:
    names = [
        (node.module, alias.name)
        for node in ast.walk(parsed(TARGET.read_text()))
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("appmode")
        for alias in node.names
    ]
    assert len(names) >= 5
    missing = [
        f"{module}.{name}"
        for module, name in names
        if module is not None and not hasattr(importlib.import_module(module), name)
    ]
    assert not missing
