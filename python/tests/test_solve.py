"""mlcp.solve and mlcp.Problem on dense and sparse problems: answers checked independently."""

import re

import numpy as np
import pytest
import scipy.sparse as sp

import mlcp
from conftest import DATA, SEED_M, SEED_Q, cli, natural_map_residual


def test_seed_lemke_example():
    r = mlcp.solve(SEED_M, SEED_Q, solver="lemke")
    assert r.status == "converged" and r.converged
    assert r.solver == "lemke"
    np.testing.assert_allclose(r.x, [20 / 19, 21 / 19, 0], atol=1e-12)
    np.testing.assert_allclose(r.w, [0, 0, 12 / 19], atol=1e-12)
    np.testing.assert_allclose(r.w, SEED_M @ r.x + SEED_Q, atol=1e-14)
    assert natural_map_residual(SEED_M, SEED_Q, [0] * 3, [np.inf] * 3, r.x) < 1e-12
    assert r.residual < 1e-12 and r.iterations == 3


def spd_tridiagonal(n):
    main = np.full(n, 4.0)
    off = np.full(n - 1, -1.0)
    return sp.diags([off, main, off], [-1, 0, 1], format="csr")


@pytest.mark.parametrize("solver", ["auto", "pgs", "dantzig", "lemke"])
def test_sparse_lcp_agrees_with_dense(solver):
    n = 60
    A = spd_tridiagonal(n)
    b = np.sin(np.arange(n))  # about half the rows active
    r = mlcp.solve(A, b, solver=solver, tol=1e-10, max_iter=5000)
    assert r.status == "converged", r.message
    assert natural_map_residual(A.toarray(), b, np.zeros(n), np.full(n, np.inf), r.x) < 1e-9
    dense = mlcp.solve(A.toarray(), b, solver="dantzig")
    np.testing.assert_allclose(r.x, dense.x, atol=1e-8)
    assert 0 < np.count_nonzero(r.x) < n


def test_sparse_input_kinds_and_duplicates():
    """coo with duplicate entries (summed), csc and sparse arrays all give the same problem."""
    A = spd_tridiagonal(5)
    coo = A.tocoo()
    rows = np.concatenate([coo.row, [0]])
    cols = np.concatenate([coo.col, [0]])
    vals = np.concatenate([coo.data - np.where(coo.row + coo.col == 0, 1.0, 0.0), [1.0]])
    dup = sp.coo_matrix((vals, (rows, cols)), shape=(5, 5))
    b = -np.ones(5)
    ref = mlcp.solve(A, b, solver="dantzig").x
    for M in (dup, A.tocsc(), sp.csr_array(A)):
        p = mlcp.Problem(M, b)
        assert p.is_sparse
        np.testing.assert_allclose(p.A.toarray(), A.toarray())
        np.testing.assert_allclose(mlcp.solve(p, solver="dantzig").x, ref, atol=1e-14)


def test_boxed_findex_problem():
    # One contact normal (row 0) and a friction row (row 1) bounded by mu |x0|, mu = 0.5.
    A = np.array([[2.0, 0.5], [0.5, 1.0]])
    b = np.array([-1.0, -2.0])
    lo, hi, findex = np.array([0.0, -0.5]), np.array([np.inf, 0.5]), np.array([-1, 0])
    for solver in ("pgs", "dantzig", "auto"):
        r = mlcp.solve(A, b, lo, hi, findex, solver=solver)
        assert r.converged, (solver, r.message)
        assert abs(r.x[1]) <= 0.5 * r.x[0] + 1e-12
        assert natural_map_residual(A, b, lo, hi, r.x, findex) < 1e-9


def test_not_converged_is_a_status():
    r = mlcp.solve(spd_tridiagonal(40), np.sin(np.arange(40)), solver="pgs", max_iter=2)
    assert r.status == "max-iterations" and not r.converged
    assert r.iterations == 2 and r.residual > 1e-10
    assert r.x.shape == (40,)


def test_guess_is_the_start():
    A, b = spd_tridiagonal(30), np.sin(np.arange(30))
    exact = mlcp.solve(A, b, solver="dantzig").x
    cold = mlcp.solve(A, b, solver="pgs", max_iter=3)
    warm = mlcp.solve(A, b, solver="pgs", max_iter=3, guess=exact)
    assert warm.residual < 1e-10 < cold.residual


def test_arrays_are_views_not_copies():
    p = mlcp.Problem(SEED_M, SEED_Q)
    assert np.shares_memory(p.b, p.b) and np.shares_memory(p.A, p.A)
    p.b[:] = [-1.0, -1.0, -1.0]  # writes into the problem itself
    r = p.solve(solver="lemke")
    np.testing.assert_allclose(r.w, SEED_M @ r.x - 1.0, atol=1e-14)
    assert r.x.flags.owndata is False  # handed over from the solver's own vector


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(solver="nope"), "unknown solver 'nope'"),
        (dict(lo=[1, 1, 1], hi=[0, 0, 0]), "row 0: lo = 1 > hi = 0"),
        (dict(findex=[-1, 5, -1]), "findex"),
        (dict(guess=[1.0, 2.0]), "guess has 2 entries, expected 3"),
    ],
)
def test_bad_input_raises_value_error(kwargs, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        mlcp.solve(SEED_M, SEED_Q, **kwargs)


def test_bad_shapes_raise_value_error():
    with pytest.raises(ValueError):
        mlcp.solve(SEED_M, SEED_Q[:2])
    with pytest.raises(ValueError, match="2-D"):
        mlcp.solve(SEED_Q, SEED_Q)
    bad = SEED_M.copy()
    bad[1, 1] = np.nan
    with pytest.raises(ValueError):
        mlcp.solve(bad, SEED_Q)


def test_solvers_listed():
    names = mlcp.solvers()
    assert {"auto", "pgs", "dantzig", "lemke", "ldlt"} <= set(names)


# The solver settings of `mlcp solve`: Options' fields and the typed parameters (newton=,
# dantzig=, lemke=), checked by the same code as the CLI's options.


def friction_problems(count=10, contacts=4, mu=0.8, seed=1):
    """Random friction-coupled problems: per contact a normal row and two tangent rows bounded by
    mu |x_normal|, A = J J^T + 0.1 I."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        n = 3 * contacts
        J = rng.normal(size=(n, 8))
        A, b = J @ J.T + 0.1 * np.eye(n), rng.normal(size=n)
        lo, hi, findex = np.zeros(n), np.full(n, np.inf), np.full(n, -1)
        for c in range(contacts):
            for i in (3 * c + 1, 3 * c + 2):
                lo[i], hi[i], findex[i] = -mu, mu, 3 * c
        out.append((A, b, lo, hi, findex))
    return out


def test_newton_params_change_the_solve():
    A, b = spd_tridiagonal(60), np.sin(np.arange(60))
    default = mlcp.solve(A, b, solver="newton")
    no_sweeps = mlcp.solve(A, b, solver="newton", newton={"cold_sweeps": 0})
    many_sweeps = mlcp.Problem(A, b).solve(solver="newton", newton={"cold_sweeps": 50})
    assert default.converged and no_sweeps.converged and many_sweeps.converged
    # pgs sweeps before the first Newton step: without them more steps, with many none.
    assert no_sweeps.iterations > default.iterations > many_sweeps.iterations == 0
    np.testing.assert_allclose(no_sweeps.x, default.x, atol=1e-9)


def test_dantzig_params_change_the_solve():
    A, b, lo, hi, findex = friction_problems()[9]
    default = mlcp.solve(A, b, lo, hi, findex, solver="dantzig")
    plain = mlcp.solve(A, b, lo, hi, findex, solver="dantzig", dantzig={"anderson_depth": 1})
    assert default.converged and plain.converged
    assert plain.iterations != default.iterations  # no extrapolation of the friction bounds
    assert natural_map_residual(A, b, lo, hi, plain.x, findex) < 1e-9


def test_lemke_params_reach_the_solver_named_chained_or_chosen_by_auto():
    named = mlcp.solve(SEED_M, SEED_Q, solver="lemke", lemke={"max_rows": 2})
    assert named.status == "unsupported" and "maxRows = 2" in named.message
    assert mlcp.solve(SEED_M, SEED_Q, solver="lemke").converged
    # auto picks lemke (A_22 = 0) with newton behind it: newton answers when lemke refuses.
    assert mlcp.solve(SEED_M, SEED_Q, solver="auto").solver == "lemke"
    chosen = mlcp.solve(SEED_M, SEED_Q, solver="auto", lemke={"max_rows": 2})
    assert chosen.converged and chosen.solver == "newton" and chosen.fallbacks == 1
    chained = mlcp.solve(SEED_M, SEED_Q, solver="lemke>newton", lemke={"max_rows": 2})
    assert chained.solver == "newton" and chained.fallbacks == 1


def test_options_fields():
    assert mlcp.solve(SEED_M, SEED_Q, solver="lemke").iterations == 3
    r = mlcp.solve(SEED_M, SEED_Q, solver="lemke", max_pivots=1)
    assert r.status == "max-iterations" and r.iterations == 1
    A, b = spd_tridiagonal(60), np.sin(np.arange(60))
    every = mlcp.solve(A, b, solver="pgs", max_iter=5000).iterations
    fifth = mlcp.solve(A, b, solver="pgs", max_iter=5000, check_every=5).iterations
    assert every % 5 != 0 and fifth == -(-every // 5) * 5  # checked every 5th sweep only
    A, b, lo, hi, findex = friction_problems()[0]
    assert mlcp.solve(A, b, lo, hi, findex, solver="dantzig").converged
    stock = mlcp.solve(A, b, lo, hi, findex, solver="dantzig", friction_bounds="fixed-once")
    assert stock.status == "failed"  # bounds fixed from an intermediate normal, as ODE's


def test_flags_and_numpy_values_are_accepted():
    A, b = spd_tridiagonal(30), np.sin(np.arange(30))
    r = mlcp.solve(A, b, solver="newton",
                   newton={"pivoting_break_cycles": False, "pivoting_steps": np.int64(0),
                           "proximal": np.float64(1e-2)})
    assert r.converged
    for solver, name, kind, default, _, _ in mlcp._mlcp.solver_params():  # defaults accepted
        value = bool(default) if kind == "bool" else (int(default) if kind == "int" else default)
        assert mlcp.solve(A, b, solver=solver, **{solver: {name: value}}).converged, name


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        (dict(newton={"pivoting_stepz": 1}), ValueError,
         "newton: unknown parameter 'pivoting_stepz' (closest: pivoting_steps; known: cold_sweeps"),
        (dict(lemke={"cold_sweeps": 1}), ValueError, "lemke: unknown parameter 'cold_sweeps'"),
        (dict(newton={"cold_sweeps": -1}), ValueError,
         "newton: cold_sweeps: expected a whole number >= 0, got '-1'"),
        (dict(newton={"cold_sweeps": 2.5}), ValueError, "expected a whole number >= 0, got '2.5'"),
        (dict(dantzig={"stall_damping": 0}), ValueError,
         "dantzig: stall_damping: expected a number in (0, 1], got '0'"),
        (dict(lemke={"refactor_period": 0}), ValueError,
         "refactor_period: expected a whole number >= 1"),
        (dict(check_every=0), ValueError, "check_every: expected a whole number >= 1, got '0'"),
        (dict(max_pivots=-2), ValueError, "max_pivots: expected a whole number >= 0, got '-2'"),
        (dict(pivot_tolerance=2.0), ValueError, "pivot_tolerance: expected a number in [0, 1]"),
        (dict(friction_bounds="fixed"), ValueError,
         "friction_bounds: expected exact or fixed-once, got 'fixed'"),
        (dict(tol=-1.0), ValueError, "tol: expected a number in [1e-300, 1e300], got '-1'"),
        (dict(newton=[("cold_sweeps", 1)]), TypeError, "newton must be a dict"),
        (dict(newton={"cold_sweeps": "1"}), TypeError, "cold_sweeps must be a number or a bool"),
        (dict(newton={1: 1}), TypeError, "parameter names are str"),
        (dict(max_pivots=1.5), TypeError, "max_pivots must be an int"),
        (dict(newtn={"cold_sweeps": 1}), TypeError, "newtn"),
    ],
)
def test_bad_settings_raise_naming_the_setting(kwargs, error, message):
    with pytest.raises(error, match=re.escape(message)):
        mlcp.solve(SEED_M, SEED_Q, solver="newton", **kwargs)


@pytest.mark.parametrize(
    "python, cli_args, message",
    [
        (dict(newton={"cold_sweeps": -1}), ["--newton", "cold_sweeps=-1"],
         "cold_sweeps: expected a whole number >= 0, got '-1'"),
        (dict(dantzig={"stall_damping": 2}), ["--dantzig", "stall-damping=2"],
         "expected a number in (0, 1], got '2'"),
        (dict(check_every=0), ["--check-every", "0"], "expected a whole number >= 1, got '0'"),
        (dict(friction_bounds="x"), ["--friction-bounds", "x"],
         "expected exact or fixed-once, got 'x'"),
    ],
)
def test_the_cli_refuses_the_same_values_with_the_same_words(python, cli_args, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        mlcp.solve(SEED_M, SEED_Q, **python)
    code, _, err = cli("solve", DATA / "seed_lemke.json", *cli_args)
    assert code == 2 and message in err, err


def test_the_cli_takes_the_same_parameters():
    code, out, _ = cli("solve", DATA / "seed_lemke.json", "--solver", "lemke", "--lemke",
                       "max-rows=2")
    assert code == 1 and "unsupported" in out
    code, out, _ = cli("solve", DATA / "seed_lemke.json", "--solver", "auto", "--lemke",
                       "max-rows=2,dense-rows=0", "--newton", "cold-sweeps=0")
    assert code == 0 and "-> lemke>newton): converged" in out
