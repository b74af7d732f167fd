"""The package's Python source parsed, for the tests that read its code."""

from __future__ import annotations

import ast


def parsed(text: str) -> ast.Module:
    """`ast.parse(text)`, parsed again should CPython 3.11 lose count of its own depth
    (SystemError "AST constructor recursion depth mismatch", python/cpython#106905): it
    happened once, in a worker whose earlier tests had left a D-Bus client's thread."""
    try:
        return ast.parse(text)
    except SystemError:
        return ast.parse(text)
