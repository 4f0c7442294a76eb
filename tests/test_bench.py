"""Correctness of the benchmark code (not timed): references agree with the engines, quick mode writes the table."""

import json

import numpy as np
import pandas as pd
import pytest

from netrepro.scale import bench
from netrepro.engines.riccati import Sensor, covariance_paths


def test_reference_loop_matches_engine(rng):
    for n in (1, 2, 3):
        A, Q, c, r, P0 = bench._system(n)
        arr = rng.random((6, 30)) < 0.6
        ours = np.asarray(covariance_paths(P0, A, Q, [Sensor(c[None, :], [[r]])], arr, keep="last")).reshape(6, n, n)
        assert np.allclose(ours, bench.reference_covariance_loop(P0, A, Q, c, r, arr), rtol=1e-12)
        if n == 1:
            assert np.allclose(ours, bench.reference_covariance_loop(P0, A, Q, c, r, arr, floats=True), rtol=1e-12)


def test_reference_ge_loop_has_the_right_law():
    arr = bench.reference_ge_loop(np.random.default_rng(0), 400, 200, 0.2, 0.6)
    assert abs(arr.mean() - 0.75) < 0.02  # stationary P(arrival) = q / (p + q)
    stay = (arr[:, 1:] & arr[:, :-1]).sum() / arr[:, :-1].sum()
    assert abs(stay - 0.8) < 0.02


def test_median_time_is_the_median_of_the_timed_calls(monkeypatch):
    """On a fake clock: the warm-up call is not timed, the result is the median sample, and with
    ``min_time`` each sample is the time per call of a loop lasting at least ``min_time``."""
    from types import SimpleNamespace

    clock = [0.0]
    monkeypatch.setattr(bench, "time", SimpleNamespace(perf_counter=lambda: clock[0]))
    durations = iter([100.0, 1.0, 5.0, 2.0])  # warm-up, then three timed calls

    def call():
        clock[0] += next(durations)

    assert bench.median_time(call, repeats=3) == 2.0
    durations = iter([100.0] + [1.0] * 3 + [3.0] + [0.5] * 5)  # 3 calls reach 2.5 s; then 1 call; then 5
    assert bench.median_time(call, repeats=3, min_time=2.5) == 1.0  # samples 1.0, 3.0, 0.5 per call
    assert next(durations, None) is None


def test_job_times_reads_snakemake_metadata(tmp_path):
    import base64
    meta = tmp_path / ".snakemake" / "metadata"
    meta.mkdir(parents=True)
    out = "results/x.csv"
    (meta / base64.urlsafe_b64encode(out.encode()).decode()).write_text(
        json.dumps({"rule": "r1", "starttime": 10.0, "endtime": 14.5}))
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "x.csv.meta.json").write_text(json.dumps({"wall_time_s": 3.0}))
    jobs = bench._job_times(tmp_path)
    assert jobs.iloc[0]["rule"] == "r1" and jobs.iloc[0]["job_s"] == 4.5 and jobs.iloc[0]["step_s"] == 3.0


@pytest.mark.slow  # runs every benchmark, one job process included (about a minute)
def test_quick_mode_writes_every_benchmark(tmp_path):
    out = tmp_path / "b.csv"
    assert bench.main(["--quick", "--out", str(out)]) == 0
    table = pd.read_csv(out)
    assert list(table.columns) == bench.COLUMNS
    names = set(table["benchmark"])
    for expected in ("blas_peak", "riccati_iid_n1", "riccati_ge_n3", "channel_ge", "lmi_sweep_two_sensor_n1",
                     "lmi_bisection", "fisher_1bit", "exact_mean", "job_exit"):
        assert expected in names
    assert not any(name.startswith("pipeline") for name in names)
    agree = table[table["metric"] == "max_rel_diff"]
    assert (agree["ours"] <= 1e-10).all()
    meta = json.loads((tmp_path / "b.csv.meta.json").read_text())
    assert meta["quick"] is True and "peak_native" in meta
