# Type stubs of the mlcp package (python/mlcp/__init__.py) for editors and type checkers.
# python/tests/test_stubs.py checks that every public name and signature here matches the module.
import concurrent.futures
import os
from typing import Any, Dict, Iterable, List, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, os.PathLike[str]]
_Matrix = Any  # a 2-D array-like of floats, or a scipy.sparse matrix / array
_Vector = Optional[npt.ArrayLike]

__all__ = ["Problem", "Result", "Run", "solve", "run", "solvers", "engines", "sweep",
           "stability"]

class Result:
    x: npt.NDArray[np.float64]
    w: npt.NDArray[np.float64]
    status: str
    residual: float
    iterations: int
    solver: str
    message: str
    complementarity: float
    bound_violation: float
    seconds: float
    fallbacks: int
    def __init__(self, x: npt.NDArray[np.float64], w: npt.NDArray[np.float64], status: str,
                 residual: float, iterations: int, solver: str, message: str,
                 complementarity: float, bound_violation: float, seconds: float,
                 fallbacks: int) -> None: ...
    @property
    def converged(self) -> bool: ...

class Problem:
    def __init__(self, A: _Matrix, b: npt.ArrayLike, lo: _Vector = None, hi: _Vector = None,
                 findex: _Vector = None) -> None: ...
    @classmethod
    def load(cls, path: _Path) -> Problem: ...
    def save(self, path: _Path) -> None: ...
    def to_json(self) -> str: ...
    @property
    def n(self) -> int: ...
    @property
    def is_sparse(self) -> bool: ...
    @property
    def kind(self) -> str: ...
    @property
    def A(self) -> Any: ...
    @property
    def b(self) -> npt.NDArray[np.float64]: ...
    @property
    def lo(self) -> npt.NDArray[np.float64]: ...
    @property
    def hi(self) -> npt.NDArray[np.float64]: ...
    @property
    def findex(self) -> npt.NDArray[np.int32]: ...
    def solve(self, solver: str = "auto", tol: float = 1e-10, guess: _Vector = None,
              max_iter: int = 1000, relaxation: float = 1.0,
              time_budget: float = 0.0) -> Result: ...

def solve(A: Union[_Matrix, Problem], b: _Vector = None, lo: _Vector = None,
          hi: _Vector = None, findex: _Vector = None, solver: str = "auto", tol: float = 1e-10,
          guess: _Vector = None, max_iter: int = 1000, relaxation: float = 1.0,
          time_budget: float = 0.0) -> Result: ...

class Run:
    scene: str
    engine: str
    solver: str
    time_step: float
    finite: bool
    captured: List[str]
    solver_ms: npt.NDArray[np.float64]
    step_ms: npt.NDArray[np.float64]
    residual: npt.NDArray[np.float64]
    iterations: npt.NDArray[np.int32]
    status: npt.NDArray[np.str_]
    fallbacks: npt.NDArray[np.int32]
    choice: npt.NDArray[np.str_]
    contacts: npt.NDArray[np.int32]
    max_penetration: npt.NDArray[np.float64]
    joint_error: npt.NDArray[np.float64]
    energy: npt.NDArray[np.float64]
    momentum: npt.NDArray[np.float64]
    max_speed: npt.NDArray[np.float64]
    bodies: List[str]
    positions: Optional[npt.NDArray[np.float64]]
    orientations: Optional[npt.NDArray[np.float64]]
    velocities: Optional[npt.NDArray[np.float64]]
    def __init__(self, scene: str, engine: str, solver: str, time_step: float, finite: bool,
                 captured: List[str], solver_ms: npt.NDArray[np.float64], step_ms: npt.NDArray[np.float64],
                 residual: npt.NDArray[np.float64], iterations: npt.NDArray[np.int32],
                 status: npt.NDArray[np.str_], fallbacks: npt.NDArray[np.int32],
                 choice: npt.NDArray[np.str_], contacts: npt.NDArray[np.int32],
                 max_penetration: npt.NDArray[np.float64],
                 joint_error: npt.NDArray[np.float64], energy: npt.NDArray[np.float64],
                 momentum: npt.NDArray[np.float64],
                 max_speed: npt.NDArray[np.float64], bodies: List[str],
                 positions: Optional[npt.NDArray[np.float64]],
                 orientations: Optional[npt.NDArray[np.float64]],
                 velocities: Optional[npt.NDArray[np.float64]]) -> None: ...
    @property
    def steps(self) -> int: ...
    def columns(self) -> Dict[str, np.ndarray]: ...
    def to_csv(self, path: _Path) -> None: ...

def run(scene: _Path, engine: str, solver: Optional[str] = None, steps: Optional[int] = None,
        iterations: Optional[int] = None, tol: Optional[float] = None, warm_start: bool = True,
        engine_iterations: bool = False, fallback: Optional[str] = "pgs",
        fallback_residual: Optional[float] = None, time_budget: Optional[float] = None,
        pivoting_steps: Optional[int] = None, friction: Optional[str] = None,
        friction_directions: Optional[int] = None, csv: Optional[_Path] = None,
        trajectory: Optional[_Path] = None, capture: Optional[int] = None,
        capture_dir: _Path = ".", states: bool = False) -> Run: ...
def sweep(scenes: Iterable[_Path], engines: Optional[Sequence[str]] = None,
          solvers: Optional[Sequence[str]] = None, setting: str = "iterations",
          values: Sequence[float] = (), steps: Optional[int] = None, repeat: int = 1,
          warm_start: bool = True, fallback: Optional[str] = "pgs",
          executor: Optional[concurrent.futures.Executor] = None) -> Any: ...
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
              executor: Optional[concurrent.futures.Executor] = None) -> Any: ...
def solvers() -> List[str]: ...
def engines() -> List[str]: ...
