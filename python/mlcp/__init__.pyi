# Type stubs of the mlcp package (python/mlcp/__init__.py) for editors and type checkers.
# python/tests/test_stubs.py checks that every public name and signature here matches the module.
import concurrent.futures
import os
from typing import Any, Dict, Iterable, List, Literal, Optional, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, os.PathLike[str]]
_Matrix = Any  # a 2-D array-like of floats, or a scipy.sparse matrix / array
_Vector = Optional[npt.ArrayLike]

__all__ = ["Problem", "Result", "Run", "solve", "run", "solvers", "engines", "sweep",
           "stability"]

# The typed solver parameters of solve() and Problem.solve() (`mlcp solve --newton KEY=VALUE,...`
# with the names kebab-case), each with its default and accepted values; the fields of
# NewtonParams, DantzigParams (core/include/mlcp/solvers/newton.hpp, dantzig.hpp), LemkeSolver
# (lemke.hpp) and ProximalParams (proximal.hpp). Any subset may be given; an unknown name or a value out of range raises ValueError.
class _NewtonParams(TypedDict, total=False):
    cold_sweeps: int  # 10, >= 0: pgs sweeps over a cold start
    warm_sweeps: int  # 20, >= 0: pgs sweeps over a warm start above warm_sweeps_residual
    warm_sweeps_residual: float  # 0.2, >= 0
    dense_factor_max_rows: int  # 100, >= 0: most rows of the dense LU (above: sparse KLU)
    proximal: float  # 1e-3, > 0: the proximal weight's start
    proximal_max: float  # 1e3, > 0: its largest value
    max_halvings: int  # 30, >= 0: line search halvings, dense path
    sparse_max_halvings: int  # 12, >= 0: line search halvings, sparse path
    step_sweeps: int  # 10, >= 0: pgs sweeps of the fallback step
    max_stalls: int  # 3, >= 0: steps in a row without descent before the solve stops
    max_stagnation: int  # 50, >= 0: steps in a row without a new best before it stops
    nonmonotone_memory: int  # 1, >= 0: merits the line search compares with (0: monotone)
    pivoting_steps: int  # 40, >= 0: block pivoting steps after damped steps end short (0: none)
    body_pivoting_steps: int  # 120, >= 0: the same on an engine's rows
    pivoting_woodbury_rows: int  # 16, >= 0: most sliding rows solved by Woodbury
    pivoting_update_rows: int  # 40, >= 0: most changed rows for a factor update (0: refactor)
    pivoting_descent_steps: int  # 8, >= 0: descending block steps not counted as stalls
    pivoting_break_cycles: bool  # True, a flag: a 2-cycle of index sets hands over to damped steps

class _DantzigParams(TypedDict, total=False):
    breakdown_shift: float  # 1e-10, >= 0: shift of the retry after a breakdown, x max A_ii
    anderson_depth: int  # 6, >= 0: normals' history of Anderson's extrapolation (friction)
    anderson_stall: int  # 20, >= 0: passes without gain before damped iteration
    stall_damping: float  # 0.3, in (0, 1]: damping factor of that iteration

class _LemkeParams(TypedDict, total=False):
    dense_rows: int  # 50, >= 0: most rows of the dense tableau (above: factored basis)
    refactor_period: int  # 50, >= 1: pivots between refactorizations of the basis
    max_rows: int  # 5000000, >= 1: largest problem accepted, rows
    friction_lcp: bool  # True, a flag: findex friction as one LCP (False: the fixed point)

class _ProximalParams(TypedDict, total=False):
    sigma: float  # 1, > 0: alpha = sigma r^nu mean(A_ii)
    nu: float  # 1, > 0: the residual's power in alpha
    alpha_min: float  # 1e-12, > 0: smallest alpha / mean(A_ii)
    alpha_max: float  # 0.01, > 0: largest alpha / mean(A_ii)
    alpha_growth: float  # 10, > 0: factor on alpha after an inner solve ended short
    inner_factor: float  # 0.1, > 0: inner tolerance = max(tol / 10, this x residual)
    max_outer: int  # 200, >= 0: most outer steps

_FrictionBounds = Literal["exact", "fixed-once"]

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
              max_iter: int = 1000, relaxation: float = 1.0, time_budget: float = 0.0,
              max_pivots: int = 0, check_every: int = 1, pivot_tolerance: float = 1e-12,
              friction_bounds: _FrictionBounds = "exact",
              newton: Optional[_NewtonParams] = None, dantzig: Optional[_DantzigParams] = None,
              lemke: Optional[_LemkeParams] = None,
              proximal: Optional[_ProximalParams] = None) -> Result: ...

def solve(A: Union[_Matrix, Problem], b: _Vector = None, lo: _Vector = None,
          hi: _Vector = None, findex: _Vector = None, solver: str = "auto", tol: float = 1e-10,
          guess: _Vector = None, max_iter: int = 1000, relaxation: float = 1.0,
          time_budget: float = 0.0, max_pivots: int = 0, check_every: int = 1,
          pivot_tolerance: float = 1e-12, friction_bounds: _FrictionBounds = "exact",
          newton: Optional[_NewtonParams] = None, dantzig: Optional[_DantzigParams] = None,
          lemke: Optional[_LemkeParams] = None,
          proximal: Optional[_ProximalParams] = None) -> Result: ...

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
