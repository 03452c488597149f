"""mlcp.solve and mlcp.Problem on dense and sparse problems: answers checked independently."""

import numpy as np
import pytest
import scipy.sparse as sp

import mlcp
from conftest import SEED_M, SEED_Q, natural_map_residual


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
