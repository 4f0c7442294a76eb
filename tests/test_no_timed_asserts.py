"""No test asserts on the wall clock (issue 39 item 6): speed is measured by the benchmarks, which
report ratios against a reference implementation in the same run (``make bench``), never by a time
limit that passes on a quiet machine and fails on a loaded one. A hang guard (a deadline that ends
a wait with ``pytest.fail``) is not a speed requirement and stays allowed."""

import ast
import textwrap
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
CLOCKS = {"time", "perf_counter", "monotonic", "process_time", "perf_counter_ns", "monotonic_ns", "time_ns"}


def _reads_clock(node: ast.AST) -> bool:
    """Whether ``node`` calls ``time.<clock>()`` (or a bare ``perf_counter()``/``monotonic()``)."""
    for call in ast.walk(node):
        if not isinstance(call, ast.Call):
            continue
        func = call.func
        if isinstance(func, ast.Attribute) and func.attr in CLOCKS and isinstance(func.value, ast.Name) \
                and func.value.id == "time":
            return True
        if isinstance(func, ast.Name) and func.id in CLOCKS - {"time"}:
            return True
    return False


def timed_asserts(source: str) -> list[int]:
    """Line numbers of the ``assert`` statements whose test reads the clock, directly or through a
    name assigned from a clock reading earlier in the same function (``start = time.perf_counter()``)."""
    found = []
    for func in ast.walk(ast.parse(source)):
        if not isinstance(func, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        clocked = {target.id for stmt in ast.walk(func) if isinstance(stmt, ast.Assign) and _reads_clock(stmt.value)
                   for target in stmt.targets if isinstance(target, ast.Name)}
        for stmt in ast.walk(func):
            if isinstance(stmt, ast.Assert) and (
                    _reads_clock(stmt.test)
                    or any(isinstance(n, ast.Name) and n.id in clocked for n in ast.walk(stmt.test))):
                found.append(stmt.lineno)
    return sorted(set(found))


def test_the_check_finds_a_timed_assert_and_leaves_a_hang_guard():
    timed = textwrap.dedent("""
        import time
        def test_fast():
            start = time.perf_counter()
            work()
            assert time.perf_counter() - start < 5.0
        def test_fast_too():
            t0 = time.monotonic()
            work()
            elapsed = time.monotonic() - t0
            assert elapsed < 1
        def test_waits():
            deadline = time.monotonic() + 10
            while busy():
                if time.monotonic() > deadline:
                    pytest.fail("never ended")
            assert done()
    """)
    assert timed_asserts(timed) == [6, 11]


@pytest.mark.parametrize("path", sorted(TESTS.rglob("test_*.py")), ids=lambda p: str(p.relative_to(TESTS)))
def test_no_test_asserts_on_the_wall_clock(path):
    lines = timed_asserts(path.read_text())
    assert not lines, (f"{path.relative_to(TESTS)} asserts on the wall clock at line(s) {lines}: "
                       "measure speed with a benchmark (src/netrepro/scale/bench.py) instead")
