"""netrepro.engines.cvx: cvxpy imported without scipy.stats, the same cvxpy and the same numbers.

Each check runs in a fresh interpreter (the deferral only applies to a process's first import of
cvxpy; pytest's own process may already hold scipy.stats).
"""

import ast
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import netrepro

SRC = Path(netrepro.__file__).resolve().parent

# a small LMI (maximise t: [[1 - a x, x], [x, 1]] >> t I, |x| <= 2, a a parameter), solved at two parameter
# values: its solver data and solution, as exact hex floats
PROBE = """
import json, sys
import numpy as np
cp = {how}
a = cp.Parameter(value=0.3)
x, t = cp.Variable(), cp.Variable()
M = cp.bmat([[1 - a * x, cp.reshape(x, (1, 1))], [cp.reshape(x, (1, 1)), np.ones((1, 1))]])
prob = cp.Problem(cp.Maximize(t), [M - t * np.eye(2) >> 0, cp.abs(x) <= 2, t <= 5])
out = {{}}
for val in (0.3, 1.7):
    a.value = val
    data, _, _ = prob.get_problem_data(solver="CLARABEL")
    prob.solve(solver="CLARABEL")
    out[str(val)] = {{"A": [float(v).hex() for v in data["A"].toarray().ravel()],
                      "b": [float(v).hex() for v in data["b"]], "c": [float(v).hex() for v in data["c"]],
                      "x": float(x.value).hex(), "t": float(t.value).hex(), "status": prob.status}}
out["stats_loaded"] = "scipy.stats" in sys.modules
print(json.dumps(out))
"""


def run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=120, check=True)


def test_deferred_import_gives_the_same_problem_data_and_solution_as_plain_cvxpy():
    deferred = json.loads(run(PROBE.format(how="__import__('netrepro.engines.cvx', fromlist=['cp']).cp")).stdout)
    # reference: cvxpy imported as usual, scipy.stats with it
    plain = json.loads(run(PROBE.format(how="__import__('cvxpy')")).stdout)
    assert deferred.pop("stats_loaded") is False
    assert plain.pop("stats_loaded") is True
    assert deferred == plain


def test_stand_in_forwards_to_the_real_scipy_stats_and_leaves_no_trace():
    out = run("""
        import sys
        from netrepro.engines.cvx import cp
        assert "scipy.stats" not in sys.modules
        qre = sys.modules["cvxpy.atoms.quantum_rel_entr"]
        p, q = [0.2, 0.5, 0.3], [0.1, 0.6, 0.3]
        deferred = qre.entropy(p, q)          # the stand-in's entropy: loads scipy.stats on first call
        assert "scipy.stats" in sys.modules
        import scipy.stats
        assert type(scipy.stats).__name__ == "module" and scipy.stats is sys.modules["scipy.stats"]
        assert scipy.stats.norm.cdf(0.0) == 0.5
        import math
        direct = sum(pi * math.log(pi / qi) for pi, qi in zip(p, q))  # independent: the definition
        print(deferred.hex(), scipy.stats.entropy(p, q).hex(), abs(deferred - direct) < 1e-15)
        """).stdout.split()
    assert out[0] == out[1] and out[2] == "True"


def test_any_other_attribute_read_during_the_import_loads_the_real_module():
    out = run("""
        import sys
        from netrepro.engines.cvx import _DeferredStats
        stand_in = _DeferredStats("scipy.stats")
        sys.modules["scipy.stats"] = stand_in
        norm = stand_in.norm                    # not entropy: the real module is imported now
        import scipy.stats
        print(norm is scipy.stats.norm, sys.modules["scipy.stats"] is not stand_in)
        """).stdout.split()
    assert out == ["True", "True"]


def test_fallback_when_scipy_stats_is_already_imported():
    out = run("""
        import sys
        import scipy.stats
        from netrepro.engines.cvx import cp
        qre = sys.modules["cvxpy.atoms.quantum_rel_entr"]
        print(qre.entropy is scipy.stats.entropy, sys.modules["scipy.stats"] is scipy.stats)
        """).stdout.split()
    assert out == ["True", "True"]


def test_the_lmi_modules_import_cvxpy_through_the_deferred_import():
    out = run("""
        import sys
        from netrepro.papers.gainsched.design import Theorem3
        from netrepro.papers.markov.lmis import GilbertElliottLMI
        from netrepro.engines.lmi import MareStabilizabilityLMI
        import netrepro.papers.markov.lmis as lm
        lm._cp()
        print("cvxpy" in sys.modules, "scipy.stats" in sys.modules)
        """).stdout.split()
    assert out == ["True", "False"]


def _cvxpy_imports(tree):
    """(function or module node, import node) for every import of cvxpy or one of its submodules."""
    found = []
    for scope in [tree] + [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]:
        body = scope.body
        for node in body:
            if isinstance(node, ast.Import) and any(a.name.split(".")[0] == "cvxpy" for a in node.names):
                found.append((scope, node))
            if isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == "cvxpy":
                found.append((scope, node))
    return found


def _imports_cvx_before(scope, node) -> bool:
    for stmt in scope.body:
        if stmt is node:
            return False
        if isinstance(stmt, ast.ImportFrom) and (stmt.module or "").endswith("cvx") and stmt.level > 0:
            return True
    return False


def test_the_check_finds_a_direct_cvxpy_import():
    tree = ast.parse("import cvxpy as cp\ndef f():\n    from .cvx import cp\n    from cvxpy.lin_ops import lin_op\n"
                     "def g():\n    from cvxpy.constraints import PSD\n")
    bad = [ast.unparse(n) for s, n in _cvxpy_imports(tree) if not _imports_cvx_before(s, n)]
    assert bad == ["import cvxpy as cp", "from cvxpy.constraints import PSD"]


def test_no_module_imports_cvxpy_directly():
    bad = []
    for path in sorted(SRC.rglob("*.py")):
        if path.name == "cvx.py" and path.parent.name == "engines":
            continue
        for scope, node in _cvxpy_imports(ast.parse(path.read_text())):
            if not _imports_cvx_before(scope, node):
                bad.append(f"{path.relative_to(SRC)}:{node.lineno}: {ast.unparse(node)}")
    assert bad == []
