"""Sweeps and stability grids as pandas DataFrames, run on any concurrent.futures.Executor.

The C++ side plans them exactly as `mlcp sweep` and `mlcp stability` do (the same checks and
messages, the same combinations and cells) and runs one combination or cell per call; here each
call is a task for the executor, and the rows come back in the plan's order whatever the order
of execution. The runs are deterministic: only the wall times (solver_ms, step_ms,
mean_solver_ms) differ between executions. A task names its scene by its file, so a remote
worker needs the mlcp package installed and the scene files readable at the same paths.
"""

from __future__ import annotations

import concurrent.futures
import os
import warnings
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np

from . import _mlcp
from .chart import require

_STEP_COLUMNS = ("solver_ms", "step_ms", "residual", "iterations", "status", "fallbacks",
                 "choice", "contacts", "max_penetration", "joint_error", "energy", "momentum",
                 "max_speed")


def _columns(header: str) -> List[str]:
    return header.split(",")


def _map(fn: Callable[..., Any], tasks: Sequence[Tuple[Any, ...]], executor: Any) -> List[Any]:
    """fn(*task) for every task, in order: on `executor`, or on a local process pool over every
    core when it is None (a single task runs here)."""
    if executor is None and len(tasks) <= 1:
        return [fn(*t) for t in tasks]
    if executor is None:
        with concurrent.futures.ProcessPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
            return _map(fn, tasks, pool)
    futures = [executor.submit(fn, *t) for t in tasks]
    return [f.result() for f in futures]


def _sweep_task(combo: Tuple[Any, ...], steps: int, warm_start: bool, fallback: str,
                repeat: int) -> Dict[str, Any]:
    return _mlcp.sweep_run(combo, steps, warm_start, fallback, repeat)


def sweep(scenes: "Iterable[str | os.PathLike[str]]", engines: Optional[Sequence[str]] = None,
          solvers: Optional[Sequence[str]] = None,
          setting: str = "iterations", values: Sequence[float] = (), steps: Optional[int] = None,
          repeat: int = 1, warm_start: bool = True, fallback: Optional[str] = "pgs",
          executor: Optional[concurrent.futures.Executor] = None) -> Any:
    """Runs scenes x engines x solvers x values of one setting, as `mlcp sweep` does.

    Returns a pandas DataFrame with the columns of `mlcp sweep --csv`, one row per step, in the
    CLI's order. engines None: every engine built; setting "iterations" (values whole, >= 1) or
    "tolerance" (values > 0); steps None: each scene's own; repeat: passes per combination,
    each step keeping its fastest solver_ms and step_ms; fallback None or "none": no fallback.
    solvers None: the CLI's default list. A stock solver that ignores the setting runs once (setting_applies 0); pairs that cannot
    exist (bullet-* in ODE) are skipped, listed in df.attrs["skipped"]; runs that blew up keep
    their rows up to the blow-up and are listed in df.attrs["blown_up"] (with a warning).
    executor: any concurrent.futures.Executor (a dask.distributed Client's get_executor(), ...);
    None: a process pool over every local core (a thread pool runs one run at a time: the
    engines' worlds are not stepped from two threads at once). Bad input raises ValueError with the CLI's
    message.
    """
    pd = require("pandas", "sweep")

    if not 1 <= int(repeat) <= 100:
        raise ValueError(f"repeat must be 1 to 100, not {repeat}")
    if steps is not None and not steps >= 0:
        raise ValueError(f"steps must be >= 0, not {steps}")
    files = [os.path.abspath(os.fspath(s)) for s in scenes]
    n_steps = -1 if steps is None else int(steps)
    fallback = fallback or "none"
    combos, skipped = _mlcp.sweep_plan(files, list(engines or []),
                                       None if solvers is None else list(solvers), setting,
                                       [repr(v) if isinstance(v, float) else str(v)
                                        for v in values], n_steps, bool(warm_start), fallback)
    tasks = [(c, n_steps, bool(warm_start), fallback, int(repeat)) for c in combos]
    results = _map(_sweep_task, tasks, executor)
    columns = _columns(_mlcp.sweep_columns())
    frames, blown_up, differing = [], [], []
    for (_, engine, solver, set_name, value, applies), r in zip(combos, results):
        n = len(r["solver_ms"])
        label = f"{r['scene']} {engine} {solver} {set_name}={value:g}"
        if not r["finite"]:
            blown_up.append(f"{label} at step {n - 1}")
        differing += [f"{label} pass {p + 1} from step {i}" for p, i in r["differing"]]
        frame = {"setting": [set_name] * n, "value": np.full(n, value),
                 "setting_applies": np.full(n, int(applies)), "scene": [r["scene"]] * n,
                 "engine": [r["engine"]] * n, "solver": [solver] * n, "step": np.arange(n)}
        frame.update({name: r[name] for name in _STEP_COLUMNS})
        frames.append(pd.DataFrame(frame, columns=columns))
    df = (pd.concat(frames, ignore_index=True) if frames
          else pd.DataFrame({c: [] for c in columns}))
    df.attrs.update(skipped=skipped, blown_up=blown_up, differing=differing)
    if blown_up:
        warnings.warn(f"{len(blown_up)} run(s) blew up (rows kept up to the blow-up): "
                      + "; ".join(blown_up), RuntimeWarning, stacklevel=2)
    return df


def _stability_task(cell: Tuple[Any, ...], settings: Dict[str, Any]) -> Dict[str, Any]:
    return _mlcp.stability_cell(cell, settings)


def stability(engines: Optional[Sequence[str]] = None, solvers: Optional[Sequence[str]] = None,
              grids: Optional[str] = None, ratios: Optional[Sequence[float]] = None,
              heights: Optional[Sequence[int]] = None,
              time_steps: Optional[Sequence[float]] = None,
              iteration_counts: Optional[Sequence[int]] = None,
              step_height: Optional[int] = None, step_ratio: Optional[float] = None,
              cfm: Optional[float] = None, seconds: Optional[float] = None,
              iterations: Optional[int] = None, fallback: Optional[str] = None,
              quick: bool = False, max_speed: Optional[float] = None,
              failure_share: Optional[float] = None, collapse_fraction: Optional[float] = None,
              collapse_penetration: Optional[float] = None, drift: Optional[float] = None,
              executor: Optional[concurrent.futures.Executor] = None) -> Any:
    """The stability grids of `mlcp stability`: the same options, snake_case, None meaning the
    CLI's default (`mlcp stability --help`), and a pandas DataFrame with the columns of its
    CSV, one row per cell in the CLI's order. quick: a 2 x 2 grid of each kind and 1 s per cell.
    executor as in sweep(). Bad arguments raise ValueError with the CLI's message."""
    pd = require("pandas", "sweep")

    given = dict(engines=engines, solvers=solvers, grids=grids, ratios=ratios, heights=heights,
                 time_steps=time_steps, iteration_counts=iteration_counts,
                 step_height=step_height, step_ratio=step_ratio, cfm=cfm, seconds=seconds,
                 iterations=iterations, fallback=fallback, quick=quick, max_speed=max_speed,
                 failure_share=failure_share, collapse_fraction=collapse_fraction,
                 collapse_penetration=collapse_penetration, drift=drift)
    settings: Dict[str, Any] = {}
    for name, value in given.items():
        if value is None:
            continue
        if isinstance(value, (list, tuple, np.ndarray)):
            kind = int if name in ("heights", "iteration_counts") else (
                float if name in ("ratios", "time_steps") else str)
            settings[name] = [kind(v) for v in value]
            numbers = settings[name] if kind is not str else []
        else:
            settings[name] = value
            numbers = [value] if isinstance(value, (int, float)) and name != "quick" else []
        positive = name not in ("iteration_counts", "iterations", "cfm", "failure_share")
        if any(not (v > 0 if positive else v >= 0) for v in numbers):
            raise ValueError(f"{name} must be {'> 0' if positive else '>= 0'}, not {value}")
    if failure_share is not None and failure_share > 1:
        raise ValueError(f"failure_share must be in [0, 1], not {failure_share}")
    cells = _mlcp.stability_cells(settings)
    rows = _map(_stability_task, [(c, settings) for c in cells], executor)
    return pd.DataFrame(rows, columns=_columns(_mlcp.stability_columns()))
