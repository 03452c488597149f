"""A missing optional dependency raises an ImportError naming the extra that installs it."""

import sys

import pytest

import mlcp
import mlcp.chart
from conftest import SCENES


def test_missing_matplotlib_names_the_chart_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # makes `import matplotlib` fail
    with pytest.raises(ImportError, match=r"matplotlib is not installed.*'chart' extra.*"
                                          r"pip install \"mlcp\[chart\]\"") as info:
        mlcp.chart.load_pyplot()
    assert info.value.name == "matplotlib"


def test_missing_pandas_names_the_sweep_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match=r"pandas is not installed.*'sweep' extra"):
        mlcp.sweep([SCENES / "resting_box.json"], engines=["ode"], solvers=["pgs"], values=[5],
                   steps=1)
    with pytest.raises(ImportError, match=r"'sweep' extra"):
        mlcp.stability(engines=["ode"], solvers=["pgs"], quick=True)
