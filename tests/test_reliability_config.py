"""Reliability (issue 8), part 1 and 7: bad configurations and missing dependencies are refused at start.

Every bad configuration must raise :class:`netrepro.pipeline.config.ConfigError` whose message names the
key, the value and what is expected. The explicit table below holds 40 distinct bad
configurations; the property-based tests generate many more over the `intermittent` section and
the top level. The whole-workflow counterpart (nothing under results/ changes when snakemake
refuses a configuration) is in tests/test_reliability_workflow.py.
"""

import copy
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from netrepro.pipeline.config import ConfigError, DependencyError, check_dependencies, validate_config
from netrepro.pipeline.registry import paper_slugs

ROOT = Path(__file__).resolve().parents[1]
# 40 examples, or fewer under a lighter hypothesis profile (`make test-fast`)
SLOW_OK = settings(max_examples=min(40, settings.default.max_examples), deadline=None,
                   suppress_health_check=[HealthCheck.function_scoped_fixture])


def base():
    """The test configuration restricted to the reference paper (independent of other papers' sections)."""
    cfg = yaml.safe_load((ROOT / "config" / "test.yaml").read_text())
    return {"papers": ["intermittent"], "intermittent": cfg["intermittent"]}


def mutate(cfg, path, value=None, delete=False):
    node = cfg
    for key in path[:-1]:
        node = node[key]
    if delete:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return cfg


def message_of(cfg) -> str:
    with pytest.raises(ConfigError, match=r"\S") as info:  # each caller checks the text of the message
        validate_config(cfg)
    return str(info.value)


S = ("intermittent", "scalar")
T = ("intermittent", "two_sensor")
NAN, INF = float("nan"), float("inf")

# (id, path, value or DELETE, fragments the message must contain: key, value, expectation)
DELETE = object()
BAD = [
    ("R2-negative", S + ("R2",), -0.5, ["intermittent.scalar.R2", "-0.5", "R2 > 0"]),
    ("R2-zero", S + ("R2",), 0, ["intermittent.scalar.R2", "= 0", "R2 > 0"]),
    ("R1-string", S + ("R1",), "0.1", ["intermittent.scalar.R1", "'0.1'", "process noise variance"]),
    ("R1-inf", S + ("R1",), INF, ["intermittent.scalar.R1", "inf", "finite number"]),
    ("R1-nan", S + ("R1",), NAN, ["intermittent.scalar.R1", "nan", "finite number"]),
    ("a-stable", S + ("a",), 0.5, ["intermittent.scalar.a", "0.5", "|a| > 1"]),
    ("a-minus-stable", S + ("a",), -0.9, ["intermittent.scalar.a", "-0.9", "|a| > 1"]),
    ("a-bool", S + ("a",), True, ["intermittent.scalar.a", "True", "|a| > 1"]),
    ("a-list", S + ("a",), [1.5], ["intermittent.scalar.a", "[1.5]", "|a| > 1"]),
    ("Ep0-negative", S + ("Ep0",), -10.0, ["intermittent.scalar.Ep0", "-10.0", "E(p0) > 0"]),
    ("horizon-string", S + ("horizon",), "sixty", ["intermittent.scalar.horizon", "'sixty'", "integer in [2, 5000]"]),
    ("horizon-float", S + ("horizon",), 30.5, ["intermittent.scalar.horizon", "30.5", "integer in [2, 5000]"]),
    ("horizon-too-long", S + ("horizon",), 10**6, ["intermittent.scalar.horizon", "1000000", "[2, 5000]"]),
    ("horizon-1", S + ("horizon",), 1, ["intermittent.scalar.horizon", "= 1", "[2, 5000]"]),
    ("exact-horizon-huge", S + ("exact_horizon",), 40, ["intermittent.scalar.exact_horizon", "40", "[1, 22]"]),
    ("horizon-below-exact", S + ("horizon",), 5, ["intermittent.scalar.exact_horizon", "must not exceed",
                                                   "'intermittent.scalar.horizon' = 5"]),
    ("n-paths-small", S + ("n_paths",), 5, ["intermittent.scalar.n_paths", "= 5", ">= 100"]),
    ("n-paths-negative", S + ("n_paths",), -1000, ["intermittent.scalar.n_paths", "-1000", ">= 100"]),
    ("block-size-zero", S + ("block_size",), 0, ["intermittent.scalar.block_size", "= 0", ">= 10"]),
    ("n-chunks-zero", S + ("n_chunks",), 0, ["intermittent.scalar.n_chunks", "= 0", "chunks"]),
    ("seed-negative", S + ("seed",), -1, ["intermittent.scalar.seed", "-1", "seed"]),
    ("seed-float", S + ("seed",), 1.5, ["intermittent.scalar.seed", "1.5", "integer"]),
    ("seed-string", S + ("seed",), "abc", ["intermittent.scalar.seed", "'abc'", "seed"]),
    ("seed-2^32", S + ("seed",), 2**32, ["intermittent.scalar.seed", "4294967296", "2^32"]),
    ("seed-missing", S + ("seed",), DELETE, ["intermittent.scalar.seed", "missing", "root random seed"]),
    ("offsets-empty", S + ("lambda_offsets",), [], ["intermittent.scalar.lambda_offsets", "[]", "offsets"]),
    ("offset-not-probability", S + ("lambda_offsets",), [0.9], ["intermittent.scalar.lambda_offsets", "0.9",
                                                                 "not a probability"]),
    ("offset-out-of-range", S + ("lambda_offsets",), [2.0], ["intermittent.scalar.lambda_offsets", "2.0",
                                                              "[-1, 1]"]),
    ("scalar-typo-key", S + ("horizn",), 30, ["intermittent.scalar.horizn", "30", "not a known key"]),
    ("scalar-not-mapping", S, 5, ["intermittent.scalar", "5", "object"]),
    ("sigma2-one", T + ("sigma2",), [0.2], ["intermittent.two_sensor.sigma2", "[0.2]", "two positive"]),
    ("sigma2-negative", T + ("sigma2",), [0.2, -0.5], ["intermittent.two_sensor.sigma2", "-0.5", "two positive"]),
    ("sigma2-three", T + ("sigma2",), [0.2, 0.5, 0.1], ["intermittent.two_sensor.sigma2", "0.1", "two positive"]),
    ("check-lambda1-above-1", T + ("check_lambda1",), 1.2, ["intermittent.two_sensor.check_lambda1", "1.2",
                                                              "probability"]),
    ("check-lambda1-negative", T + ("check_lambda1",), -0.1, ["intermittent.two_sensor.check_lambda1", "-0.1",
                                                                "probability"]),
    ("check-offset-zero", T + ("check_offset",), 0.0, ["intermittent.two_sensor.check_offset", "0.0",
                                                         "(0, 0.5]"]),
    ("grid-one-point", T + ("lambda1_grid",), 1, ["intermittent.two_sensor.lambda1_grid", "= 1", "[2, 2001]"]),
    ("bisection-tol-large", T + ("bisection_tol",), 0.5, ["intermittent.two_sensor.bisection_tol", "0.5",
                                                            "(0, 0.1]"]),
    ("two-sensor-seed-none", T + ("seed",), None, ["intermittent.two_sensor.seed", "None", "seed"]),
    ("two-sensor-missing", T, DELETE, ["intermittent.two_sensor", "missing"]),
    ("papers-unknown", ("papers",), ["nonsense"], ["papers", "'nonsense'", "list of paper slugs"]),
    ("papers-empty", ("papers",), [], ["papers", "[]", "list of paper slugs"]),
    ("papers-duplicate", ("papers",), ["intermittent", "intermittent"], ["papers", "list of paper slugs"]),
    ("papers-string", ("papers",), "intermittent", ["papers", "'intermittent'", "list of paper slugs"]),
    ("papers-missing", ("papers",), DELETE, ["papers", "missing", "list of paper slugs"]),
    ("section-missing", ("intermittent",), DELETE, ["'intermittent' is missing", "papers", "intermittent.schema"]),
    ("section-not-mapping", ("intermittent",), [1, 2], ["config key 'intermittent'", "[1, 2]", "object"]),
    ("top-level-typo", ("intermitent",), {}, ["intermitent", "not a known key", "intermittent"]),
]


def test_each_bad_configuration_changes_the_valid_one():
    """Every case has its own id and really changes the (valid) test configuration at its path."""
    assert len({case[0] for case in BAD}) == len(BAD)
    validate_config(base())
    for name, path, value, _ in BAD:
        node = base()
        for key in path[:-1]:
            node = node[key]
        present = isinstance(node, dict) and path[-1] in node
        if value is DELETE:
            assert present, name
        elif present:
            original = node[path[-1]]
            assert not (type(original) is type(value) and original == value), name


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_bad_configuration_is_named(case):
    _, path, value, fragments = case
    cfg = mutate(base(), path, delete=True) if value is DELETE else mutate(base(), path, copy.deepcopy(value))
    msg = message_of(cfg)
    for fragment in fragments:
        assert fragment in msg, f"{fragment!r} not in message:\n{msg}"


@pytest.mark.parametrize("config", [None, [], "papers: [intermittent]", 3], ids=["none", "list", "string", "int"])
def test_configuration_that_is_not_a_mapping(config):
    assert "expected a mapping" in message_of(config)


def test_every_problem_is_reported_at_once():
    cfg = base()
    mutate(cfg, S + ("R2",), -1)
    mutate(cfg, T + ("check_lambda1",), 3.0)
    mutate(cfg, S + ("seed",), -4)
    msg = message_of(cfg)
    assert all(k in msg for k in ("scalar.R2", "two_sensor.check_lambda1", "scalar.seed"))


# ----------------------------------------------------------------------------- property-based
# For every key of the intermittent section: values the schema describes as invalid.
NOT_NUMBERS = st.one_of(st.text(max_size=5), st.booleans(), st.none(), st.lists(st.integers(), max_size=2))
NONFINITE = st.sampled_from([NAN, INF, -INF])


def positive_number_bad():
    return st.one_of(NOT_NUMBERS, NONFINITE, st.floats(max_value=0.0, allow_nan=False, allow_infinity=False))


def int_range_bad(lo, hi=None):
    below = st.integers(max_value=lo - 1)
    above = st.integers(min_value=hi + 1) if hi is not None else st.nothing()
    floats = st.floats(allow_nan=False, allow_infinity=False).filter(lambda x: x != int(x))
    return st.one_of(below, above, floats, NOT_NUMBERS, NONFINITE)


SCALAR_BAD = {
    "a": st.one_of(st.floats(min_value=-1.0, max_value=1.0), NOT_NUMBERS, NONFINITE),
    "R1": positive_number_bad(),
    "R2": positive_number_bad(),
    "Ep0": positive_number_bad(),
    "horizon": int_range_bad(2, 5000),
    "exact_horizon": int_range_bad(1, 22),
    "n_paths": int_range_bad(100, 100000000),
    "block_size": int_range_bad(10, 10000000),
    "seed": int_range_bad(0, 2**32 - 1),
    "lambda_offsets": st.one_of(st.just([]), NOT_NUMBERS.filter(lambda v: not isinstance(v, list)),
                                st.lists(st.floats(min_value=1.0001, max_value=1e9), min_size=1, max_size=3)),
}
TWO_BAD = {
    "a": st.one_of(st.floats(min_value=-1.0, max_value=1.0), NOT_NUMBERS, NONFINITE),
    "R1": positive_number_bad(),
    "sigma2": st.one_of(st.lists(st.floats(min_value=0.1, max_value=9), max_size=1),
                        st.lists(st.floats(min_value=0.1, max_value=9), min_size=3, max_size=4),
                        st.tuples(st.floats(max_value=0.0), st.floats(min_value=0.1, max_value=1)).map(list)),
    "lambda1_grid": int_range_bad(2, 2001),
    "bisection_tol": st.one_of(st.floats(max_value=0.0, allow_nan=False), st.floats(min_value=0.1001, max_value=1e6),
                               NOT_NUMBERS, NONFINITE),
    "check_lambda1": st.one_of(st.floats(min_value=1.0001, max_value=1e9), st.floats(max_value=-1e-9, min_value=-1e9),
                               NOT_NUMBERS, NONFINITE),
    "check_offset": st.one_of(st.floats(max_value=0.0, allow_nan=False), st.floats(min_value=0.5001, max_value=9),
                              NOT_NUMBERS, NONFINITE),
    "check_horizon": int_range_bad(10, 5000),
    "check_paths": int_range_bad(100),
    "seed": int_range_bad(0, 2**32 - 1),
}


@st.composite
def bad_section_value(draw):
    section, table = draw(st.sampled_from([("scalar", SCALAR_BAD), ("two_sensor", TWO_BAD)]))
    key = draw(st.sampled_from(sorted(table)))
    return section, key, draw(table[key])


@SLOW_OK
@given(bad_section_value())
def test_property_any_out_of_schema_value_is_refused_and_named(case):
    section, key, value = case
    msg = message_of(mutate(base(), ("intermittent", section, key), value))
    assert f"intermittent.{section}.{key}" in msg
    assert "Expected" in msg or "expected" in msg or "must" in msg or "is not a probability" in msg


@SLOW_OK
@given(st.text(alphabet="abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=12),
       st.sampled_from(["top", "scalar", "two_sensor"]), st.integers())
def test_property_unknown_keys_are_refused_and_named(name, where, value):
    cfg = base()
    node = {"top": cfg, "scalar": cfg["intermittent"]["scalar"], "two_sensor": cfg["intermittent"]["two_sensor"]}[where]
    if name in node or (where == "top" and name in paper_slugs()):
        return
    node[name] = value
    msg = message_of(cfg)
    assert name in msg and "not a known key" in msg


@SLOW_OK
@given(st.lists(st.text(min_size=1, max_size=10), min_size=1, max_size=4))
def test_property_papers_must_be_known_slugs(papers):
    known = set(paper_slugs())
    cfg = base()
    cfg["papers"] = papers
    if set(papers) <= known and len(set(papers)) == len(papers):
        return
    assert "papers" in message_of(cfg)


@st.composite
def valid_intermittent(draw):
    """Random configurations inside every documented range: they must be accepted."""
    cfg = base()
    sc, ts = cfg["intermittent"]["scalar"], cfg["intermittent"]["two_sensor"]
    sc["a"] = draw(st.one_of(st.floats(1.01, 10.0), st.floats(-10.0, -1.01)))
    for key in ("R1", "R2", "Ep0"):
        sc[key] = draw(st.floats(1e-6, 1e6))
    sc["horizon"] = draw(st.integers(2, 5000))
    sc["exact_horizon"] = draw(st.integers(1, min(22, sc["horizon"])))
    sc["n_paths"] = draw(st.integers(100, 10**8))
    sc["block_size"] = draw(st.integers(10, 10**7))
    sc["seed"] = draw(st.integers(0, 2**32 - 1))
    lam_c = 1 - 1 / sc["a"] ** 2
    sc["lambda_offsets"] = draw(st.lists(st.floats(-lam_c, 1 - lam_c), min_size=1, max_size=3))
    ts["sigma2"] = draw(st.lists(st.floats(1e-6, 1e3), min_size=2, max_size=2))
    ts["check_lambda1"] = draw(st.floats(0.0, 1.0))
    ts["seed"] = draw(st.integers(0, 2**32 - 1))
    return cfg


@SLOW_OK
@given(valid_intermittent())
def test_property_documented_ranges_are_accepted(cfg):
    validate_config(cfg)


# ----------------------------------------------------------------------------- dependencies (part 7)
def test_missing_and_outdated_packages_are_named():
    with pytest.raises(DependencyError, match="surely-not-installed-pkg") as info:
        check_dependencies(["numpy>=2", "surely-not-installed-pkg>=1", "numpy>=999"])
    msg = str(info.value)
    assert "'surely-not-installed-pkg' is missing" in msg
    assert "'numpy' has version" in msg and "numpy>=999" in msg
    assert "make" in msg and "pip install" in msg


def test_installed_environment_passes_the_check():
    checked = check_dependencies()
    assert any(r.startswith("cvxpy") for r in checked) and any(r.startswith("clarabel") for r in checked)


BLOCKER = """
import sys
BLOCKED = set({blocked!r})

class _Block:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {{name!r}} (blocked by the test)", name=name)
        return None

sys.meta_path.insert(0, _Block())
"""


def run_blocked(tmp_path, blocked, code):
    hook = tmp_path / "hook"
    hook.mkdir(exist_ok=True)
    (hook / "sitecustomize.py").write_text(BLOCKER.format(blocked=sorted(blocked)))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(hook), os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=120)


@pytest.mark.parametrize("blocked", [["cvxpy"], ["clarabel"], ["papermill"], ["numba"], ["cvxpy", "nbconvert"]])
def test_blocked_import_gives_clear_message(tmp_path, blocked):
    proc = run_blocked(tmp_path, blocked, """
        from netrepro.pipeline.config import check_dependencies, DependencyError
        try:
            check_dependencies()
        except DependencyError as exc:
            print(exc)
            raise SystemExit(3)
        """)
    assert proc.returncode == 3, proc.stderr
    for name in blocked:
        assert f"required package '{name}' is missing" in proc.stdout
    assert "Fix: run `make`" in proc.stdout


def test_a_crippled_solver_is_refused_at_start_up_with_the_reinstall_command(tmp_path):
    # clarabel present (found by its spec) but failing on import, as a broken build or a missing
    # shared library does: found-only checks passed it and every LMI job then failed with a traceback
    fake = tmp_path / "site" / "clarabel"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('libclarabel.so: cannot open shared object file')\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path / "site"), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        from netrepro.pipeline.config import check_dependencies, DependencyError
        try:
            check_dependencies()
        except DependencyError as exc:
            print(exc)
            raise SystemExit(3)
        """)], capture_output=True, text=True, env=env, cwd=ROOT, timeout=120)
    assert proc.returncode == 3, proc.stdout + proc.stderr
    assert "required package 'clarabel'" in proc.stdout and "cannot be imported" in proc.stdout
    assert "libclarabel.so" in proc.stdout and "pip install --force-reinstall 'clarabel" in proc.stdout


def test_the_solver_of_the_lmi_engine_is_imported_at_start_up():
    from netrepro.pipeline.config import IMPORTED_AT_START
    from netrepro.engines.cvx import SOLVER

    assert SOLVER.lower() in IMPORTED_AT_START


def test_paper_needing_a_missing_package_is_not_reported_as_a_missing_paper(tmp_path):
    # a paper's checks module that imports a missing package (pandas, blocked). The packaged papers keep
    # checks.py light (no pandas), so the import of such a module is simulated by a finder that
    # loads the real checks module after an `import pandas`
    proc = run_blocked(tmp_path, ["pandas"], """
        import importlib.abc, importlib.util, sys
        import yaml
        from netrepro.pipeline.config import validate_config, DependencyError

        class NeedsPandas(importlib.abc.MetaPathFinder, importlib.abc.Loader):
            def find_spec(self, name, path, target=None):
                if name == "netrepro.papers.intermittent.checks":
                    return importlib.util.spec_from_loader(name, self)
            def create_module(self, spec):
                return None
            def exec_module(self, module):
                import pandas  # noqa: F401  (blocked)

        sys.meta_path.insert(0, NeedsPandas())
        cfg = yaml.safe_load(open("config/test.yaml"))
        try:
            validate_config({"papers": ["intermittent"], "intermittent": cfg["intermittent"]})
        except DependencyError as exc:
            print(exc)
            raise SystemExit(3)
        """)
    assert proc.returncode == 3, proc.stderr
    assert "needs the package 'pandas'" in proc.stdout


def test_math_isfinite_guard_is_used_for_all_numbers():
    # a NaN hidden deep in a list is still named by its full key
    cfg = base()
    cfg["intermittent"]["two_sensor"]["sigma2"] = [0.2, NAN]
    msg = message_of(cfg)
    assert "intermittent.two_sensor.sigma2" in msg and "nan" in msg
    cfg["intermittent"]["two_sensor"]["sigma2"] = [0.2, 0.5]
    validate_config(cfg)  # the same list with a finite number is accepted: the NaN is what is rejected
