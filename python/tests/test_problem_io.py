"""mlcp.Problem.load / save: mlcp-problem/1 JSON and Siconos .dat files, and their errors."""

import json

import numpy as np
import pytest
import scipy.sparse as sp

import mlcp
from conftest import DATA, SEED_M, SEED_Q, cli_error


def test_load_seed_file():
    p = mlcp.Problem.load(DATA / "seed_lemke.json")
    assert p.n == 3 and not p.is_sparse and p.kind == "standard-lcp"
    np.testing.assert_array_equal(p.A, SEED_M)
    np.testing.assert_array_equal(p.b, SEED_Q)
    np.testing.assert_allclose(p.solve(solver="lemke").x, [20 / 19, 21 / 19, 0], atol=1e-12)


def test_dense_round_trip(tmp_path):
    lo, hi, findex = [0, -1, -0.5], [np.inf, 1, 0.5], [-1, -1, 0]
    p = mlcp.Problem(SEED_M + 5 * np.eye(3), SEED_Q, lo, hi, findex)
    path = tmp_path / "boxed.json"
    p.save(path)
    assert json.loads(path.read_text())["format"] == "mlcp-problem/1"
    q = mlcp.Problem.load(path)
    assert q.kind == "findex" and not q.is_sparse
    for name in ("A", "b", "lo", "hi", "findex"):
        np.testing.assert_array_equal(getattr(q, name), getattr(p, name))


def test_sparse_round_trip_stays_sparse(tmp_path):
    A = sp.random(30, 30, density=0.1, random_state=1, format="csr") + 30 * sp.eye(30)
    p = mlcp.Problem(A, -np.ones(30))
    path = tmp_path / "sparse.json"
    p.save(path)
    q = mlcp.Problem.load(str(path))
    assert q.is_sparse
    np.testing.assert_allclose(q.A.toarray(), A.toarray(), rtol=1e-15)


def test_siconos_dense_file(tmp_path):
    # n, storage 0 (dense), the matrix size twice, then A column by column, then q.
    columns = "\n".join(" ".join(f"{v:g}" for v in SEED_M[:, j]) for j in range(3))
    path = tmp_path / "seed.dat"
    path.write_text(f"3\n0\n3 3\n3 3\n{columns}\n-1 -10 6\n")
    p = mlcp.Problem.load(path)
    np.testing.assert_array_equal(p.A, SEED_M)
    r = p.solve(solver="lemke")
    np.testing.assert_allclose(r.x, [20 / 19, 21 / 19, 0], atol=1e-12)


@pytest.mark.parametrize("name", ["bad/truncated.json", "bad/lo_above_hi.json",
                                  "bad/findex_range.json", "bad/short.dat", "missing.json"])
def test_bad_file_raises_the_cli_message(name):
    path = DATA / name
    expected = cli_error("solve", path)
    with pytest.raises(ValueError) as e:
        mlcp.Problem.load(path)
    # The CLI names the file once more for problems that parse but do not validate.
    assert expected.endswith(str(e.value)), (expected, str(e.value))
