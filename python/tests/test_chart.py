"""mlcp.chart: the charts of tools/chart.py drawn from mlcp.sweep's and mlcp.stability's frames."""

import concurrent.futures

import pandas as pd
import pytest

import mlcp
import mlcp.chart
from conftest import SCENES

pytest.importorskip("matplotlib")


def test_work_precision_from_a_sweep(tmp_path):
    df = mlcp.sweep([SCENES / "stack_10.json"], engines=["ode"], solvers=["pgs", "dantzig"],
                    values=[3, 30], steps=4, executor=concurrent.futures.ThreadPoolExecutor(1))
    figures = mlcp.chart.work_precision(df)
    assert list(figures) == ["stack_10"]
    lines = [line for ax in figures["stack_10"].axes for line in ax.get_lines()
             if line.get_label().startswith("ode / ")]
    assert {line.get_label() for line in lines} == {"ode / pgs", "ode / dantzig"}
    written = mlcp.chart.work_precision(df, out=tmp_path)
    assert sorted(p.rsplit(".", 1)[1] for p in written) == ["png", "svg"]
    with pytest.raises(ValueError, match="missing column"):
        mlcp.chart.work_precision(df.drop(columns=["residual"]))


def test_heatmap_from_a_stability_grid(tmp_path):
    df = mlcp.stability(engines=["ode"], solvers=["dantzig"], quick=True, grids="mass",
                        executor=concurrent.futures.ThreadPoolExecutor(1))
    figures = mlcp.chart.heatmap(df)
    assert list(figures) == ["stability_stack_mass_ratio"]
    assert figures["stability_stack_mass_ratio"].axes[0].get_title() == "ode / dantzig"
    bad = pd.DataFrame(df).assign(outcome="wobbly")
    with pytest.raises(ValueError, match="unknown outcome 'wobbly'"):
        mlcp.chart.heatmap(bad)
