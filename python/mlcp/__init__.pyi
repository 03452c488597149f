# Type stubs of the mlcp package (python/mlcp/__init__.py) for editors and type checkers.
# python/tests/test_stubs.py checks that every public name and signature here matches the module.
import os
from typing import Any, Dict, List, Optional, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, os.PathLike[str]]
_Matrix = Any  # a 2-D array-like of floats, or a scipy.sparse matrix / array
_Vector = Optional[npt.ArrayLike]

__all__ = ["Problem", "Result", "Run", "solve", "run", "solvers", "engines"]

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
              max_iter: int = 1000, relaxation: float = 1.0) -> Result: ...

def solve(A: Union[_Matrix, Problem], b: _Vector = None, lo: _Vector = None,
          hi: _Vector = None, findex: _Vector = None, solver: str = "auto", tol: float = 1e-10,
          guess: _Vector = None, max_iter: int = 1000, relaxation: float = 1.0) -> Result: ...

class Run:
    scene: str
    engine: str
    solver: str
    time_step: float
    finite: bool
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
                 solver_ms: npt.NDArray[np.float64], step_ms: npt.NDArray[np.float64],
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
        fallback: Optional[str] = "pgs", fallback_residual: Optional[float] = None,
        states: bool = False) -> Run: ...
def solvers() -> List[str]: ...
def engines() -> List[str]: ...
