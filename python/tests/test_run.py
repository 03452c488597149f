"""mlcp.run: scene files in both engines, the per-step measures of `mlcp run --csv`."""

import csv

import numpy as np
import pytest

import mlcp
from conftest import SCENES, cli, cli_error

# The engines the rigid-scene checks below run in (bullet-multibody gives bullet's answers on
# scenes without articulated bodies).
ENGINES = [e for e in mlcp.engines() if e != "bullet-multibody"]


def test_every_engine_built():
    assert mlcp.engines() == ["bullet", "bullet-multibody", "ode"]


@pytest.mark.parametrize("engine", mlcp.engines())
def test_articulated_scene_in_every_engine(engine):
    solver = "ode-world" if engine == "ode" else "bullet-si"
    run = mlcp.run(SCENES / "limit_chain.json", engine, solver=solver, steps=20)
    assert run.steps == 20 and run.finite and run.engine == engine
    assert np.all(run.max_speed < 5)


@pytest.mark.parametrize("engine", ENGINES)
def test_stack_with_dantzig(engine):
    run = mlcp.run(SCENES / "stack_10.json", engine, solver="dantzig", steps=30)
    assert run.steps == 30 and run.finite
    assert run.scene == "stack_10" and run.engine == engine and run.solver == "dantzig"
    for name, column in run.columns().items():
        assert len(column) == 30, name
    assert run.solver_ms.dtype == np.float64 and run.iterations.dtype.kind == "i"
    assert np.all(run.status == "converged")
    assert np.all(run.residual < 1e-6)
    assert run.contacts[-1] > 0 and np.all(run.max_penetration < 0.05)
    assert all(c.startswith("dantzig:") for c in run.choice)


def test_states_follow_the_bodies():
    """A box resting on the ground stays where it was put (0, 0, 0.5), upright."""
    run = mlcp.run(SCENES / "resting_box.json", "ode", solver="dantzig", steps=60, states=True)
    assert run.positions.shape == (60, len(run.bodies), 3)
    assert run.orientations.shape == (60, len(run.bodies), 4)
    np.testing.assert_allclose(np.linalg.norm(run.orientations, axis=2), 1.0, atol=1e-9)
    box = run.bodies.index("box")
    np.testing.assert_allclose(run.positions[:, box], [[0, 0, 0.5]] * 60, atol=2e-3)
    np.testing.assert_allclose(np.abs(run.orientations[:, box, 0]), 1.0, atol=1e-6)
    assert np.abs(run.velocities[:, box]).max() < 0.05
    plain = mlcp.run(SCENES / "resting_box.json", "ode", solver="dantzig", steps=2)
    assert plain.positions is None and plain.bodies == run.bodies


def test_stock_solver_residual_not_measured():
    run = mlcp.run(SCENES / "stack_10.json", "bullet", solver="bullet-si", steps=5)
    assert np.all(np.isnan(run.residual))


def test_scene_defaults_and_solver_sweep():
    """steps None: the scene's own count; a sweep is a loop."""
    worst = {s: mlcp.run(SCENES / "hinge_motor_limits.json", "ode", solver=s, steps=20).residual.max()
             for s in ("dantzig", "pgs")}
    assert worst["dantzig"] < 1e-9
    assert worst["pgs"] >= worst["dantzig"]


@pytest.mark.parametrize("engine", ENGINES)
def test_csv_matches_the_cli(engine, tmp_path):
    args = (SCENES / "stack_10.json", "--engine", engine, "--solver", "dantzig", "--steps", 20)
    code, _, err = cli("run", *args, "--csv", tmp_path / "cli.csv")
    assert code == 0, err
    mlcp.run(SCENES / "stack_10.json", engine, solver="dantzig", steps=20).to_csv(tmp_path / "py.csv")
    with open(tmp_path / "cli.csv") as a, open(tmp_path / "py.csv") as b:
        ours, theirs = list(csv.DictReader(b)), list(csv.DictReader(a))
    assert list(ours[0].keys()) == list(theirs[0].keys())
    assert len(ours) == len(theirs) == 20
    for o, t in zip(ours, theirs):
        for key in ("scene", "engine", "solver", "step", "iterations", "status", "contacts",
                    "choice", "fallbacks"):
            assert o[key] == t[key], key
        for key in ("energy", "momentum", "max_speed", "max_penetration"):
            assert float(o[key]) == pytest.approx(float(t[key]), rel=1e-7, abs=1e-12), key


@pytest.mark.parametrize(
    "scene, engine, solver",
    [("stack_10.json", "physx", "dantzig"), ("stack_10.json", "bullet", "no-such-solver"),
     ("no_such_scene.json", "ode", "dantzig")],
)
def test_bad_run_raises_the_cli_message(scene, engine, solver):
    expected = cli_error("run", SCENES / scene, "--engine", engine, "--solver", solver)
    with pytest.raises(ValueError) as e:
        mlcp.run(SCENES / scene, engine, solver=solver, steps=1)
    assert str(e.value) == expected


def test_negative_steps_refused():
    with pytest.raises(ValueError, match="steps"):
        mlcp.run(SCENES / "stack_10.json", "ode", steps=-1)


def test_cli_run_settings_are_taken(tmp_path):
    """friction, friction_directions, time_budget, pivoting_steps, engine_iterations: the CSV
    written by the Python run equals the CLI's with the same settings."""
    settings = dict(solver="lemke", friction="cone", friction_directions=8, time_budget=0.0,
                    pivoting_steps=0, steps=5)
    run = mlcp.run(SCENES / "stack_10.json", "bullet", csv=tmp_path / "py.csv", **settings)
    assert run.finite and np.all(run.residual < 1e-6)
    code, _, err = cli("run", SCENES / "stack_10.json", "--engine", "bullet", "--solver", "lemke",
                       "--friction", "cone", "--friction-directions", 8, "--time-budget", 0,
                       "--pivoting-steps", 0, "--steps", 5, "--csv", tmp_path / "cli.csv")
    assert code == 0, err
    with open(tmp_path / "cli.csv") as a, open(tmp_path / "py.csv") as b:
        theirs, ours = list(csv.DictReader(a)), list(csv.DictReader(b))
    assert [r["iterations"] for r in ours] == [r["iterations"] for r in theirs]
    assert [r["energy"] for r in ours] == [r["energy"] for r in theirs]
    box = mlcp.run(SCENES / "stack_10.json", "bullet", solver="lemke", steps=5)
    assert not np.array_equal(box.iterations, run.iterations)  # the cone is another problem
    # The engine's fixed sweeps: 7 on the stack's one island, checked once, no fallback.
    fixed = mlcp.run(SCENES / "stack_10.json", "ode", solver="pgs", iterations=7, steps=40,
                     engine_iterations=True)
    free = mlcp.run(SCENES / "stack_10.json", "ode", solver="pgs", iterations=7, steps=40)
    assert np.all(fixed.iterations == 7) and np.all(fixed.fallbacks == 0)
    assert free.iterations.sum() > fixed.iterations.sum()  # short of 1e-6: the fallback ran


def test_capture_writes_the_step_problems(tmp_path):
    run = mlcp.run(SCENES / "stack_10.json", "ode", solver="dantzig", steps=4, capture=2,
                   capture_dir=tmp_path / "cap")
    assert run.captured and all(f.endswith(".json") for f in run.captured)
    problem = mlcp.Problem.load(run.captured[0])
    assert problem.n > 0 and mlcp.solve(problem, solver="dantzig").converged
    with pytest.raises(ValueError, match="is not one of the 4 steps"):
        mlcp.run(SCENES / "stack_10.json", "ode", steps=4, capture=4, capture_dir=tmp_path)


@pytest.mark.parametrize("option, value, kwargs", [
    ("--friction-directions", 2, dict(solver="lemke", friction="cone", friction_directions=2)),
    ("--friction", "cone", dict(solver="pgs", friction="cone")),
])
def test_bad_run_settings_raise(option, value, kwargs):
    with pytest.raises(ValueError) as e:
        mlcp.run(SCENES / "stack_10.json", "bullet", steps=1, **kwargs)
    if option == "--friction":  # refused by the engine: the CLI says the same
        assert str(e.value) == cli_error("run", SCENES / "stack_10.json", "--engine", "bullet",
                                         "--solver", "pgs", "--friction", "cone", "--steps", 1)
    with pytest.raises(ValueError, match="friction: 'disc' is not box or cone"):
        mlcp.run(SCENES / "stack_10.json", "bullet", steps=1, friction="disc")
