"""No function of src/ longer than 120 lines (issue 39: "no god function"), compiled kernels aside.

A function's length is its ``def`` line to its last line (docstring included), as ``ast`` reports them. A
function compiled by numba (decorated by ``njit``, ``jit``, ``vectorize``, ... imported from numba) is
exempt: splitting a kernel costs call overhead inside its compiled loop. The decorator decides, not a list
of names.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
MAX_LINES = 120
NUMBA_DECORATORS = {"njit", "jit", "vectorize", "guvectorize", "cfunc", "stencil", "generated_jit", "intrinsic",
                    "overload", "jitclass"}


def _numba_names(tree: ast.Module) -> set:
    """The local names that refer to numba or to something imported from it (``import numba as nb`` -> nb)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {a.asname or a.name.split(".")[0] for a in node.names if a.name.split(".")[0] == "numba"}
        elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "numba":
            names |= {a.asname or a.name for a in node.names}
    return names


def _is_compiled(func: ast.FunctionDef, numba_names: set) -> bool:
    """Whether a decorator of ``func`` is a numba compiler (``@njit``, ``@njit(...)``, ``@numba.jit``, ...)."""
    for dec in func.decorator_list:
        target = dec.func if isinstance(dec, ast.Call) else dec
        if isinstance(target, ast.Name) and target.id in numba_names and target.id in NUMBA_DECORATORS:
            return True
        if isinstance(target, ast.Attribute) and target.attr in NUMBA_DECORATORS:
            root = target.value
            while isinstance(root, ast.Attribute):
                root = root.value
            if isinstance(root, ast.Name) and root.id in numba_names:
                return True
    return False


def long_functions(source: str, limit: int = MAX_LINES) -> list:
    """``(name, lines)`` of every function (nested ones too) of ``source`` longer than ``limit`` lines,
    compiled kernels aside."""
    tree = ast.parse(source)
    numba_names = _numba_names(tree)
    return [(node.name, node.end_lineno - node.lineno + 1) for node in ast.walk(tree)
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
            and node.end_lineno - node.lineno + 1 > limit and not _is_compiled(node, numba_names)]


def _body(n: int) -> str:
    return "".join(f"    x{i} = {i}\n" for i in range(n))


def test_the_check_fails_a_long_function_and_exempts_only_compiled_kernels():
    long_def = "def god():\n" + _body(MAX_LINES)  # 121 lines
    assert long_functions(long_def) == [("god", MAX_LINES + 1)]
    assert long_functions("def ok():\n" + _body(MAX_LINES - 1)) == []
    nested = "def outer():\n    def inner():\n" + "".join("    " + line for line in _body(MAX_LINES).splitlines(True))
    assert ("inner", MAX_LINES + 1) in long_functions(nested)
    compiled = "from numba import njit\n\n@njit(cache=True)\n" + long_def
    assert long_functions(compiled) == []
    assert long_functions("import numba as nb\n\n@nb.njit\n" + long_def) == []
    # a decorator named like numba's but not from numba exempts nothing
    assert long_functions("from functools import cache as njit\n\n@njit\n" + long_def) == [("god", MAX_LINES + 1)]
    assert long_functions("import functools\n\n@functools.lru_cache\n" + long_def) == [("god", MAX_LINES + 1)]


@pytest.mark.parametrize("path", sorted(SRC.rglob("*.py")), ids=lambda p: str(p.relative_to(SRC)))
def test_no_function_over_120_lines(path):
    found = long_functions(path.read_text(encoding="utf-8"))
    assert not found, f"{path.relative_to(SRC)}: functions over {MAX_LINES} lines (split them into named steps): {found}"
