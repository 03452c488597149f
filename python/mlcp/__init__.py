"""mlcp: mixed linear complementarity (MLCP) solvers for physics engines, from Python.

Every solver answers the same question,

    find x, w with  w = A x + b,  lo <= x <= hi,
    x_i = lo_i => w_i >= 0,   x_i = hi_i => w_i <= 0,   lo_i < x_i < hi_i => w_i = 0,

with friction coupling (findex[i] = j >= 0: row i's bounds are lo_i |x_j| .. hi_i |x_j|), and
every answer carries the scaled natural-map residual, recomputed from the problem.

    import mlcp, numpy as np
    r = mlcp.solve(np.array([[2., 1.], [1., 2.]]), np.array([-1., -1.]), solver="lemke")
    r.x, r.w, r.status, r.residual          # (1/3, 1/3), (0, 0), "converged", ~1e-17

    p = mlcp.Problem.load("problem.json")  # mlcp-problem/1 JSON, or a Siconos LCP .dat file
    run = mlcp.run("scenes/stack_10.json", "bullet", solver="dantzig", steps=100)
    run.residual.max(), run.solver_ms.mean()  # per-step measures, as `mlcp run` writes them
    df = mlcp.sweep(["scenes/stack_10.json"], solvers=["pgs", "dantzig"], values=[5, 20])
    mlcp.chart.work_precision(df)             # `mlcp sweep --csv`'s rows; mlcp.stability(...)

Invalid input (a malformed problem or file, an unknown solver, engine or scene) raises
ValueError with the message the `mlcp` program prints; a solver that did not converge is not an
error: its Result says so in `status` ("max-iterations", "failed", ...).
"""

from __future__ import annotations

import dataclasses
import numbers
import os
from typing import Any, Dict, List, Mapping, Optional, Tuple

import numpy as np

from . import _mlcp, chart
from .studies import stability, sweep

__all__ = ["Problem", "Result", "Run", "solve", "run", "solvers", "engines", "sweep",
           "stability"]


def _vector(name: str, v: Any, n: int, default: Optional[float]) -> Optional[np.ndarray]:
    """v as a contiguous float64 vector of n entries (a scalar is repeated), None for default."""
    if v is None:
        return None
    a = np.asarray(v, dtype=np.float64)
    if a.ndim == 0:
        return np.full(n, float(a))
    if a.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, not {a.ndim}-D")
    return np.ascontiguousarray(a)


def _index(findex: Any) -> Optional[np.ndarray]:
    if findex is None:
        return None
    a = np.asarray(findex)
    if a.ndim != 1 or (a.size and a.dtype.kind not in "iu"):
        raise ValueError("findex must be a 1-D array of integers (-1: no friction coupling)")
    return np.ascontiguousarray(a, dtype=np.int32)


def _is_sparse(A: Any) -> bool:
    return type(A).__module__.startswith("scipy.sparse")


def _core_problem(A: Any, b: Any, lo: Any, hi: Any, findex: Any) -> "_mlcp.Problem":
    bv = _vector("b", b, 0, None)
    if bv is None:
        raise ValueError("b is required")
    n = bv.shape[0]
    args = (bv, _vector("lo", lo, n, 0.0), _vector("hi", hi, n, np.inf), _index(findex))
    if _is_sparse(A):
        csr = A.tocsr().astype(np.float64, copy=False)
        if not csr.has_canonical_format:
            csr = csr.copy()
            csr.sum_duplicates()
        rows, cols = csr.shape
        return _mlcp.Problem.sparse(rows, cols, np.asarray(csr.indptr, dtype=np.int32),
                                    np.asarray(csr.indices, dtype=np.int32),
                                    np.ascontiguousarray(csr.data), *args)
    a = np.asarray(A, dtype=np.float64)
    if a.ndim != 2:
        raise ValueError(f"A must be a 2-D array or a scipy.sparse matrix, not {a.ndim}-D")
    return _mlcp.Problem.dense(np.asfortranarray(a), *args)


@dataclasses.dataclass(frozen=True)
class Result:
    """One solve's answer and how it was reached (see mlcp/result.hpp)."""

    x: np.ndarray  # the solution (or the last iterate), n entries
    w: np.ndarray  # A x + b at x
    status: str  # "converged", "least-squares", "max-iterations", "time-limit", "failed", ...
    residual: float  # scaled natural-map residual at x, recomputed from the problem
    iterations: int  # sweeps, or pivots for pivoting methods
    solver: str  # the solver that produced x (auto and fallback chains name their choice)
    message: str  # why it stopped, in words
    complementarity: float  # max_i of the complementarity gap at x
    bound_violation: float  # max_i distance of x_i outside its effective bounds
    seconds: float  # wall time of the solve
    fallbacks: int  # solvers tried and rejected before `solver`

    @property
    def converged(self) -> bool:
        return self.status == "converged"


class Problem:
    """An MLCP: w = A x + b, lo <= x <= hi, findex (see the module's doc).

    A is a 2-D array (copied once into the problem) or a scipy.sparse matrix (kept sparse); lo
    defaults to 0 and hi to +inf (a standard LCP), findex to no coupling. Raises ValueError with
    the core's message when the problem is not well formed (sizes, NaN, lo > hi, findex out of
    range or chained). b, lo, hi and A are views of the problem's own storage, not copies.
    """

    __slots__ = ("_core",)

    def __init__(self, A: Any, b: Any, lo: Any = None, hi: Any = None, findex: Any = None):
        self._core = _core_problem(A, b, lo, hi, findex)

    @classmethod
    def _wrap(cls, core: "_mlcp.Problem") -> "Problem":
        p = cls.__new__(cls)
        p._core = core
        return p

    @classmethod
    def load(cls, path: "str | os.PathLike[str]") -> "Problem":
        """Reads an mlcp-problem/1 .json file or a Siconos LCP .dat file (by extension)."""
        return cls._wrap(_mlcp.Problem.load(os.fspath(path)))

    def save(self, path: "str | os.PathLike[str]") -> None:
        """Writes mlcp-problem/1 JSON (dense rows or sparse triplets, as A is stored)."""
        self._core.save(os.fspath(path))

    def to_json(self) -> str:
        return self._core.to_json()

    @property
    def n(self) -> int:
        return self._core.n

    @property
    def is_sparse(self) -> bool:
        return self._core.is_sparse

    @property
    def kind(self) -> str:
        """"linear", "standard-lcp", "boxed", "findex" or "empty" (mlcp::ProblemClass)."""
        return self._core.kind

    @property
    def A(self) -> Any:
        """A dense view (F-ordered ndarray) or a scipy.sparse.csr_array over A's storage."""
        if not self._core.is_sparse:
            return self._core.dense_A
        import scipy.sparse

        indptr, indices, data = self._core.csr
        n = self._core.n
        return scipy.sparse.csr_array((data, indices, indptr), shape=(n, n), copy=False)

    @property
    def b(self) -> np.ndarray:
        return self._core.b

    @property
    def lo(self) -> np.ndarray:
        return self._core.lo

    @property
    def hi(self) -> np.ndarray:
        return self._core.hi

    @property
    def findex(self) -> np.ndarray:
        """Per row the index of its normal row, or -1."""
        f = self._core.findex
        return np.asarray(f, dtype=np.int32) if f else np.full(self.n, -1, dtype=np.int32)

    def solve(self, solver: str = "auto", tol: float = 1e-10, guess: Any = None,
              max_iter: int = 1000, relaxation: float = 1.0, time_budget: float = 0.0,
              max_pivots: int = 0, check_every: int = 1, pivot_tolerance: float = 1e-12,
              friction_bounds: str = "exact", newton: Optional[Mapping[str, Any]] = None,
              dantzig: Optional[Mapping[str, Any]] = None,
              lemke: Optional[Mapping[str, Any]] = None,
              proximal: Optional[Mapping[str, Any]] = None) -> Result:
        """Solves with a registered solver (see solvers()); `guess` is the start point; the
        settings are those of `mlcp solve`, snake_case (see solve())."""
        g = _vector("guess", guess, self.n, None)
        options = dict(tol=tol, max_iter=max_iter, relaxation=relaxation,
                       time_budget=time_budget, max_pivots=max_pivots, check_every=check_every,
                       pivot_tolerance=pivot_tolerance, friction_bounds=friction_bounds)
        params = _params(newton=newton, dantzig=dantzig, lemke=lemke, proximal=proximal)
        return Result(**self._core.solve(solver, options, params, g))

    def __repr__(self) -> str:
        storage = "sparse" if self.is_sparse else "dense"
        return f"mlcp.Problem(n={self.n}, {self.kind}, {storage})"


def solve(A: Any, b: Any = None, lo: Any = None, hi: Any = None, findex: Any = None,
          solver: str = "auto", tol: float = 1e-10, guess: Any = None, max_iter: int = 1000,
          relaxation: float = 1.0, time_budget: float = 0.0, max_pivots: int = 0,
          check_every: int = 1, pivot_tolerance: float = 1e-12, friction_bounds: str = "exact",
          newton: Optional[Mapping[str, Any]] = None, dantzig: Optional[Mapping[str, Any]] = None,
          lemke: Optional[Mapping[str, Any]] = None,
          proximal: Optional[Mapping[str, Any]] = None) -> Result:
    """Solves w = A x + b, lo <= x <= hi (findex) with the named solver ("auto" chooses).

    A may also be a Problem (then b, lo, hi and findex are not given). The settings are those of
    `mlcp solve`, snake_case, with its defaults and checks: tol is the target of the scaled
    natural-map residual, max_iter the sweep (or outer iteration) limit, relaxation the SOR
    factor of gs/pgs, time_budget the wall-clock limit in seconds (0: none; when it runs out the
    best answer so far comes back as "time-limit"), max_pivots the pivot limit of pivoting
    methods (0: 50 n + 100), check_every the sweeps between residual checks of iterative
    methods, pivot_tolerance the pivot magnitude treated as zero, friction_bounds "exact" or
    "fixed-once" (stock ODE's and Bullet's friction handling).

    newton, dantzig, lemke and proximal are dicts of that solver's typed parameters (`mlcp solve --newton
    KEY=VALUE,...`; names and defaults in the stub, mlcp/__init__.pyi), e.g.
    newton={"pivoting_steps": 0, "cold_sweeps": 0}; they apply wherever that solver runs (named,
    in a chain "a>b", or chosen by auto). An unknown name or a value out of range raises
    ValueError naming it; a value that is not a number or a bool raises TypeError. A result that
    did not reach tol says so in its status.
    """
    if isinstance(A, Problem):
        if b is not None or lo is not None or hi is not None or findex is not None:
            raise ValueError("solve(problem): b, lo, hi and findex come from the problem")
        problem = A
    else:
        problem = Problem(A, b, lo, hi, findex)
    return problem.solve(solver, tol, guess, max_iter, relaxation, time_budget, max_pivots,
                         check_every, pivot_tolerance, friction_bounds, newton, dantzig, lemke,
                         proximal)


def _params(**groups: Optional[Mapping[str, Any]]) -> List[Tuple[str, str, float, str]]:
    """The typed parameters given as (solver, name, value, value as written), checked for their
    types here and for their names and values by the C++ side (the CLI's checks)."""
    out = []
    for solver, given in groups.items():
        if given is None:
            continue
        if not isinstance(given, Mapping):
            raise TypeError(f"{solver} must be a dict of parameter names to values, "
                            f"not {type(given).__name__}")
        for key, value in given.items():
            if not isinstance(key, str):
                raise TypeError(f"{solver}: parameter names are str, not {key!r}")
            if not isinstance(value, (numbers.Real, np.bool_)):
                raise TypeError(f"{solver}: {key} must be a number or a bool, "
                                f"not {type(value).__name__}")
            out.append((solver, key, float(value), str(value)))
    return out


_RUN_COLUMNS = ("solver_ms", "step_ms", "residual", "iterations", "status", "fallbacks", "choice",
                "contacts", "max_penetration", "joint_error", "energy", "momentum", "max_speed")


@dataclasses.dataclass(frozen=True)
class Run:
    """A scene run's measures, one entry per step (the columns of `mlcp run --csv`; their
    meaning and units: scenes/include/mlcp/scene/world.hpp)."""

    scene: str
    engine: str
    solver: str  # the solver asked for
    time_step: float  # s
    finite: bool  # False: the body states became non-finite and the run stopped there
    captured: List[str]  # with run(..., capture=STEP): the problem files written
    solver_ms: np.ndarray  # wall time of the constraint solves, ms
    step_ms: np.ndarray  # wall time of the whole step, ms
    residual: np.ndarray  # worst scaled residual of the step's problems (NaN: not measured)
    iterations: np.ndarray  # summed over islands
    status: np.ndarray  # worst status over islands ("converged", ...), str
    fallbacks: np.ndarray
    choice: np.ndarray  # which solver answered the islands, e.g. "dantzig:3 ldlt:1", str
    contacts: np.ndarray
    max_penetration: np.ndarray  # m
    joint_error: np.ndarray  # m
    energy: np.ndarray  # J
    momentum: np.ndarray  # kg m/s
    max_speed: np.ndarray  # m/s
    bodies: List[str]  # every scene body's name, static ones included, in scene order
    # With run(..., states=True), per step and body (shape steps x bodies x k), else None:
    positions: Optional[np.ndarray]  # centre of mass, world, m (k = 3)
    orientations: Optional[np.ndarray]  # body to world quaternion w, x, y, z (k = 4)
    velocities: Optional[np.ndarray]  # m/s (k = 3)

    @property
    def steps(self) -> int:
        return int(self.solver_ms.shape[0])

    def columns(self) -> Dict[str, np.ndarray]:
        """The per-step columns by name (e.g. for pandas.DataFrame(run.columns()))."""
        return {name: getattr(self, name) for name in _RUN_COLUMNS}

    def to_csv(self, path: "str | os.PathLike[str]") -> None:
        """Writes the rows `mlcp run --csv` writes (same header and columns)."""
        header = "scene,engine,solver,step," + ",".join(_RUN_COLUMNS)
        with open(path, "w", encoding="utf-8") as out:
            out.write(header + "\n")
            cols = [getattr(self, name) for name in _RUN_COLUMNS]
            for i in range(self.steps):
                cells = [self.scene, self.engine, self.solver, str(i)]
                cells += [f"{c[i]:.9g}" if c.dtype.kind == "f" else str(c[i]) for c in cols]
                out.write(",".join(cells) + "\n")


def run(scene: "str | os.PathLike[str]", engine: str, solver: Optional[str] = None,
        steps: Optional[int] = None, iterations: Optional[int] = None,
        tol: Optional[float] = None, warm_start: bool = True, engine_iterations: bool = False,
        fallback: Optional[str] = "pgs", fallback_residual: Optional[float] = None,
        time_budget: Optional[float] = None, pivoting_steps: Optional[int] = None,
        friction: Optional[str] = None, friction_directions: Optional[int] = None,
        csv: "str | os.PathLike[str] | None" = None,
        trajectory: "str | os.PathLike[str] | None" = None, capture: Optional[int] = None,
        capture_dir: "str | os.PathLike[str]" = ".", states: bool = False) -> Run:
    """Steps a scene file (mlcp-scene/1) in an engine ("bullet", "bullet-multibody" or "ode",
    see engines()). "bullet-multibody" builds the scene's articulated bodies as Bullet
    btMultiBodies (reduced coordinates) and takes the core solvers and Bullet's own ("bullet-si",
    "bullet-mlcp-dantzig", ...); "bullet" and "ode" build them as jointed rigid bodies.

    The settings of `mlcp run`, snake_case, with its defaults (`mlcp run --help`); None: the
    scene's own value (solver, steps, iterations, tol, friction, friction_directions) or the
    adapters' default (fallback_residual 1e-3, time_budget 0.05 s, pivoting_steps 40/120).
    fallback None or "none": no fallback; friction "box" or "cone"; csv and trajectory: files to
    write as `mlcp run --csv/--trajectory` does; capture: the step whose islands are written to
    capture_dir (listed in Run.captured). states: also record every body's position,
    orientation and velocity after each step.
    """
    for name, value in (("steps", steps), ("iterations", iterations), ("tol", tol),
                        ("fallback_residual", fallback_residual), ("time_budget", time_budget),
                        ("pivoting_steps", pivoting_steps),
                        ("friction_directions", friction_directions), ("capture", capture)):
        if value is not None and not value >= 0:
            raise ValueError(f"{name} must be >= 0, not {value}")

    def number(v: Any, cast: Any) -> Any:
        return -1 if v is None else cast(v)

    d = _mlcp.run(os.fspath(scene), engine, solver or "", number(steps, int),
                  number(iterations, int), number(tol, float), bool(warm_start),
                  bool(engine_iterations), fallback or "", number(fallback_residual, float),
                  number(time_budget, float), number(pivoting_steps, int), friction or "",
                  number(friction_directions, int), os.fspath(csv) if csv else "",
                  os.fspath(trajectory) if trajectory else "", number(capture, int),
                  os.fspath(capture_dir), bool(states))
    d["status"] = np.array(d["status"], dtype=str)
    d["choice"] = np.array(d["choice"], dtype=str)
    return Run(**d)


def solvers() -> List[str]:
    """The core registry's solver names ("auto", "pgs", "dantzig", "lemke", ...)."""
    return list(_mlcp.solver_names())


def engines() -> List[str]:
    """The engines this build can run scenes in ("bullet", "bullet-multibody", "ode")."""
    return list(_mlcp.engine_names())

