"""mlcp.sweep and mlcp.stability: the CLI's plans and rows as DataFrames, on any executor."""

import concurrent.futures

import numpy as np
import pandas as pd
import pytest

import mlcp
from conftest import SCENES, cli, cli_error

TIMES = ["solver_ms", "step_ms", "mean_solver_ms"]  # wall times: the only columns that may differ
SMALL = dict(engines=["bullet", "ode"], solvers=["pgs", "dantzig"], values=[5, 20], steps=6)


def small_sweep(executor):
    return mlcp.sweep([SCENES / "resting_box.json", SCENES / "stack_10.json"], **SMALL,
                      executor=executor)


def assert_same_runs(a, b):
    """Equal value for value, the wall-time columns aside (NaN equal to NaN)."""
    assert list(a.columns) == list(b.columns)
    keep = [c for c in a.columns if c not in TIMES]
    pd.testing.assert_frame_equal(a[keep], b[keep], check_exact=True)


def test_sweep_columns_and_rows_match_the_cli(tmp_path):
    scenes = [SCENES / "resting_box.json", SCENES / "stack_10.json"]
    code, _, err = cli("sweep", *scenes, "--engines", "bullet,ode", "--solvers",
                       "pgs,dantzig,ode-world", "--values", "5,20", "--steps", 6, "--csv",
                       tmp_path / "cli.csv")
    assert code == 0, err
    ours = mlcp.sweep(scenes, engines=["bullet", "ode"], solvers=["pgs", "dantzig", "ode-world"],
                      values=[5, 20], steps=6, executor=concurrent.futures.ThreadPoolExecutor(1))
    theirs = pd.read_csv(tmp_path / "cli.csv", keep_default_na=False, na_values=["nan"])
    assert list(ours.columns) == list(theirs.columns)
    assert len(ours) == len(theirs) == 2 * (2 * 2 * 2 + 1) * 6  # ode-world once, only in ode
    assert ours.attrs["skipped"] == "ode-world in bullet"
    for key in ("setting", "scene", "engine", "solver", "step", "iterations", "status",
                "fallbacks", "choice", "contacts", "setting_applies"):
        assert ours[key].tolist() == theirs[key].tolist(), key
    for key in ("value", "residual", "energy", "max_penetration", "max_speed"):
        np.testing.assert_allclose(ours[key], theirs[key], rtol=1e-7, atol=1e-12, err_msg=key)
    assert set(ours.loc[ours.solver == "ode-world", "setting_applies"]) == {0}


def test_sweep_on_a_process_pool_equals_serial():
    serial = small_sweep(concurrent.futures.ThreadPoolExecutor(1))
    assert_same_runs(small_sweep(None), serial)  # None: a local process pool
    assert (serial.groupby(["scene", "engine", "solver", "value"]).size() == 6).all()


def test_sweep_on_a_dask_cluster_equals_serial():
    distributed = pytest.importorskip("distributed")
    serial = small_sweep(concurrent.futures.ThreadPoolExecutor(1))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            on_cluster = small_sweep(client.get_executor())
    assert_same_runs(on_cluster, serial)


def test_sweep_repeat_keeps_the_fastest_times():
    args = dict(engines=["ode"], solvers=["dantzig"], values=[10], steps=5,
                executor=concurrent.futures.ThreadPoolExecutor(1))
    once = mlcp.sweep([SCENES / "stack_10.json"], **args)
    thrice = mlcp.sweep([SCENES / "stack_10.json"], repeat=3, **args)
    assert_same_runs(thrice, once)
    assert thrice.attrs["differing"] == []


@pytest.mark.parametrize("kwargs, cli_args", [
    (dict(values=[2.5]), ["--values", "2.5"]),
    (dict(values=[5], solvers=["no-such-solver"]), ["--values", "5", "--solvers",
                                                     "no-such-solver"]),
    (dict(values=[5], engines=["physx"]), ["--values", "5", "--engines", "physx"]),
    (dict(values=[0], setting="tolerance"), ["--values", "0", "--setting", "tolerance"]),
])
def test_bad_sweep_raises_the_cli_message(kwargs, cli_args, tmp_path):
    expected = cli_error("sweep", SCENES / "stack_10.json", *cli_args, "--csv",
                         tmp_path / "x.csv")
    with pytest.raises(ValueError) as e:
        mlcp.sweep([SCENES / "stack_10.json"], **kwargs)
    assert str(e.value) == expected


def test_stability_matches_the_cli(tmp_path):
    args = ["--engines", "ode", "--solvers", "dantzig,ode-quick", "--quick", "--grids", "mass"]
    code, _, err = cli("stability", *args, "--csv", tmp_path / "cli.csv")
    assert code == 0, err
    theirs = pd.read_csv(tmp_path / "cli.csv")
    ours = mlcp.stability(engines=["ode"], solvers=["dantzig", "ode-quick"], quick=True,
                          grids="mass", executor=concurrent.futures.ThreadPoolExecutor(1))
    assert list(ours.columns) == list(theirs.columns) and len(ours) == len(theirs) == 8
    for key in ("engine", "solver", "x_name", "y_name", "outcome", "scene", "steps",
                "failed_steps", "fallback_steps", "reason"):
        assert ours[key].tolist() == theirs[key].tolist(), key
    for key in ("x_value", "y_value", "max_speed", "top_displacement", "worst_residual"):
        np.testing.assert_allclose(ours[key], theirs[key], rtol=1e-7, atol=1e-12, err_msg=key)


def test_bad_stability_raises():
    with pytest.raises(ValueError, match="--grids must name mass, step or both"):
        mlcp.stability(grids="neither", quick=True)
    with pytest.raises(ValueError, match="unknown solver 'nope'"):
        mlcp.stability(solvers=["nope"], quick=True)
    with pytest.raises(ValueError, match="heights must be > 0"):
        mlcp.stability(heights=[0])
