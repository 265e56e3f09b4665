"""saltus.optimize from Python: the paper's drop (e = 0.5) with the C++ tests' figures (the jump from
−sqrt(2 g h) to e sqrt(2 g h) at sqrt(2 h / g)), the polynomials between the samples, the saved
folder byte-identical to `saltus optimize`'s and replayed by `saltus replay`, Ctrl-C stopping a
solve as KeyboardInterrupt, and bad input as ValueError."""
import json
import os
import signal
import subprocess
import threading
import time

import numpy as np
import pytest

import saltus

G, H = 9.81, 0.1


@pytest.fixture(scope="module")
def drop():
    return saltus.optimize("point_mass_drop", method="impulsive", seed=2, set={"restitution": 0.5})


def test_the_drop_jumps_with_newtons_restitution(drop):
    assert drop.feasible
    assert drop.summary["iterations"] > 0 and drop.summary["feasible"] is True
    assert drop.summary["status"] == drop.status == drop.summary["stages"][drop.summary["kept_stage"]]["status"]
    speed = np.sqrt(2 * G * H)
    assert drop.v.min() == pytest.approx(-speed, rel=1e-3)
    assert drop.v.max() == pytest.approx(0.5 * speed, rel=1e-3)
    assert drop.t[np.argmin(drop.v[:, 0])] == pytest.approx(np.sqrt(2 * H / G), abs=1e-3)
    assert drop.q.shape == (drop.t.size, 1) and drop.u.shape == (drop.t.size, 0)


def test_the_polynomials_fall_freely_between_the_samples(drop):
    t_impact = drop.t[np.argmin(drop.v[:, 0])]
    for t in np.linspace(0.01, 0.9 * t_impact, 7):
        p = drop.at(t)
        assert p["q"][0] == pytest.approx(H - 0.5 * G * t * t, abs=1e-6)
        assert p["v"][0] == pytest.approx(-G * t, abs=1e-6)
    before, after = drop.at(t_impact, "before"), drop.at(t_impact, "after")
    assert after["v"][0] - before["v"][0] == pytest.approx(1.5 * np.sqrt(2 * G * H), rel=1e-3)


def test_the_saved_folder_is_the_commands_and_replays(drop, tmp_path, saltus_binary):
    drop.save(str(tmp_path / "python"))
    subprocess.run([saltus_binary, "optimize", "point_mass_drop", "--seed", "2", "--set", "restitution=0.5",
                    "--out", str(tmp_path / "cli")], check=True, capture_output=True)
    for name in ("trajectory.csv", "variables.csv"):  # separate builds: equal to round-off
        python_lines = (tmp_path / "python" / name).read_text().splitlines()
        cli_lines = (tmp_path / "cli" / name).read_text().splitlines()
        assert len(python_lines) == len(cli_lines), name
        assert python_lines[0] == cli_lines[0], name
    replay = subprocess.run([saltus_binary, "replay", str(tmp_path / "python"), "--out", str(tmp_path / "replay")],
                            capture_output=True, text=True)
    assert replay.returncode == 0, replay.stderr
    saltus.replay(str(tmp_path / "python"), out=str(tmp_path / "python_replay"))
    python_replay = (tmp_path / "python_replay" / "replay.csv").read_text().splitlines()
    cli_replay = (tmp_path / "replay" / "replay.csv").read_text().splitlines()
    assert python_replay == cli_replay


@pytest.mark.parametrize("problem,method", [("point_mass_throw", "impulsive"), ("pendulum_conveyor", "impulsive"),
                                            ("point_mass_drop", "first-order")])
def test_every_built_in_problem_solves_as_the_command_does(problem, method, tmp_path, saltus_binary):
    s = saltus.optimize(problem, method=method)
    s.save(str(tmp_path / "python"))
    cli = subprocess.run([saltus_binary, "optimize", problem, "--method", method, "--out", str(tmp_path / "cli")],
                         capture_output=True, text=True)
    assert cli.returncode == (0 if s.feasible else 1), cli.stderr
    summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert summary["feasible"] == s.feasible
    assert summary["status"] == s.status == summary["stages"][summary["kept_stage"]]["status"]
    assert summary["largest_product"] == pytest.approx(s.summary["largest_product"], rel=1e-6, abs=1e-12)
    python_q = np.loadtxt(tmp_path / "python" / "trajectory.csv", delimiter=",", skiprows=1)
    cli_q = np.loadtxt(tmp_path / "cli" / "trajectory.csv", delimiter=",", skiprows=1)
    assert python_q.shape == cli_q.shape
    np.testing.assert_allclose(python_q, cli_q, atol=1e-6)


def test_ctrl_c_stops_a_solve_cleanly():
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        saltus.optimize("pendulum_conveyor", N=40, restarts=3)
    timer.cancel()
    assert time.monotonic() - start < 20
    assert saltus.optimize("point_mass_drop").feasible  # the module still works


def test_bad_input_is_a_value_error_and_an_infeasible_solve_can_be_an_error():
    with pytest.raises(ValueError, match="P: expected an order from 1 to 9"):
        saltus.optimize("point_mass_drop", P=12)
    with pytest.raises(ValueError, match="method"):
        saltus.optimize("point_mass_drop", method="magic")
    with pytest.raises(ValueError, match="feasibility_hessian: expected 'exact' or 'limited-memory', got 'bfgs'"):
        saltus.optimize("point_mass_drop", feasibility_hessian="bfgs")
    with pytest.raises(ValueError, match="restitution"):
        saltus.optimize("point_mass_drop", method="continuous", set={"restitution": 0.5})
    with pytest.raises(ValueError, match="seed_method: "):
        saltus.optimize("point_mass_drop", seed_method="euler")
    with pytest.raises(ValueError, match="seed_method: expected another method than the solve's own"):
        saltus.optimize("point_mass_drop", seed_method="impulsive")
    with pytest.raises(ValueError, match="resimulations: expected a non-negative integer"):
        saltus.optimize("ollie_simple", resimulations=-1)
    with pytest.raises(ValueError, match="resimulation_tracking: expected a natural frequency >= 0 rad/s"):
        saltus.optimize("ollie_simple", resimulation_tracking=-1.0)
    with pytest.raises(ValueError, match="feasibility_repeats: expected a non-negative integer, got -1"):
        saltus.optimize("point_mass_drop", feasibility_repeats=-1)
    with pytest.raises(ValueError, match="no_such_problem"):
        saltus.load_problem("no_such_problem")
    with pytest.raises(saltus.SolveError) as error:
        saltus.optimize("point_mass_drop", ipopt={"max_iter": "2"}, restarts=0, require_feasible=True)
    assert error.value.args[1] == "Maximum_Iterations_Exceeded"
    problem = saltus.load_problem("point_mass_drop", {"height": 0.2})
    assert problem.parameters["height"] == 0.2 and problem.N == 20


def test_the_feasibility_stage_can_go_without_second_derivatives():
    """feasibility_hessian="limited-memory": Ipopt's quasi-Newton, no Hessian evaluated in that stage."""
    quasi = saltus.optimize("point_mass_drop", feasibility_hessian="limited-memory", restarts=0)
    exact = saltus.optimize("point_mass_drop", restarts=0)
    assert quasi.feasible and exact.feasible
    q_stage, e_stage = quasi.summary["stages"][0], exact.summary["stages"][0]
    assert (q_stage["hessian"], q_stage["hessian_evaluations"]) == ("limited-memory", 0)
    assert e_stage["hessian"] == "exact" and e_stage["hessian_evaluations"] > 0
    # the same drop: the impact at sqrt(2 h / g)
    for s in (quasi, exact):
        jump = np.argmax(np.diff(s.v[:, 0]))
        assert abs(s.t[jump + 1] - np.sqrt(2 * H / G)) < 1e-3


def test_hints_false_solves_without_the_problems_hints(tmp_path, root):
    """A hint the drop cannot meet (the ball down at [2, 0], 0.04 s after its release from 0.1 m):
    infeasible with it, its reach in the summary; hints=False (--no-hints) solves."""
    path = tmp_path / "hinted_drop.yaml"
    text = (root / "models" / "problems" / "point_mass_drop.yaml").read_text()
    path.write_text(text + "\nhints:\n  - {at: [2, 0], gap: {ball: 0}}\n")
    hinted = saltus.optimize(str(path), restarts=0)
    assert not hinted.feasible
    assert hinted.summary["hints_used"] == 1 and len(hinted.summary["hints"]) == 1
    assert hinted.summary["hints"][0]["reachable"] is False
    unhinted = saltus.optimize(str(path), restarts=0, hints=False)
    assert unhinted.feasible and unhinted.summary["hints_used"] == 0


def test_continuation_false_solves_without_the_problems_continuation(tmp_path, root):
    """A continuation in the problem's parameters (solve.continuation): the bouncing drop's seed
    first through the inelastic drop, each step in the summary and its iterations in the total;
    continuation=False (--no-continuation) solves without it."""
    path = tmp_path / "continued_drop.yaml"
    text = (root / "models" / "problems" / "point_mass_drop.yaml").read_text()
    path.write_text(text + "\nsolve:\n  continuation:\n    - {restitution: 0}\n")
    continued = saltus.optimize(str(path), restarts=0, set={"restitution": 0.5})
    steps = continued.summary["continuation"]
    assert len(steps) == 1 and steps[0]["parameters"] == {"restitution": 0.0} and steps[0]["attempt"] == 0
    assert continued.summary["iterations"] == steps[0]["iterations"] + sum(s["iterations"] for s in continued.summary["stages"])
    assert continued.feasible
    plain = saltus.optimize(str(path), restarts=0, set={"restitution": 0.5}, continuation=False)
    assert "continuation" not in plain.summary and plain.feasible


def test_task_ipopt_reaches_the_task_stage_only(tmp_path, root):
    """task_ipopt (--task-ipopt): Ipopt options of the task stage alone. The drop with a task cost
    (its largest height): max_iter 0 there stops the task stage at its start, the feasibility
    stage iterates as before; an unknown option is a ValueError naming it."""
    path = tmp_path / "drop_with_task.yaml"
    text = (root / "models" / "problems" / "point_mass_drop.yaml").read_text()
    text = text.replace("cost:\n  penalty_weight: 1.0", "cost:\n  minimise_max: {coordinate: z, weight: 1.0}\n  penalty_weight: 1.0")
    path.write_text(text)
    free = saltus.optimize(str(path), restarts=0)
    stopped = saltus.optimize(str(path), restarts=0, task_ipopt={"max_iter": "0"})
    assert [s["name"] for s in free.summary["stages"]] == ["feasibility", "task"]
    assert free.summary["stages"][1]["iterations"] > 0
    assert stopped.summary["stages"][0]["iterations"] == free.summary["stages"][0]["iterations"]
    assert stopped.summary["stages"][1]["iterations"] == 0
    with pytest.raises(ValueError, match="no_such_option"):
        saltus.optimize(str(path), restarts=0, task_ipopt={"no_such_option": "1"})


def test_an_input_schedule_drives_the_simulation_seed(tmp_path):
    """seed_inputs (--seed-inputs): the schedule's inputs are the seed's; the problem says which
    inputs a schedule has and their bounds; a bad schedule is a ValueError naming the file and row."""
    problem = saltus.load_problem("ollie_simple", {"force_limit": 2})
    assert problem.inputs == ["back_x", "back_z", "front_x", "front_z"]
    weight = problem.parameters["rider_mass"] * problem.parameters["g"]
    assert np.allclose(problem.input_upper, 2 * weight) and np.allclose(problem.input_lower, -2 * weight)
    bad = tmp_path / "push.csv"
    bad.write_text("t,u.back_x,u.back_z,u.front_x,u.front_z\n0,0,0,0,0\n0.1,0,%g,0,0\n0.4,0,0,0,0\n" % (3 * weight))
    with pytest.raises(ValueError, match=r"--seed-inputs: .*push.csv: row 2 \(t = 0.1\): column 'u.back_z'"):
        saltus.optimize(problem, seed_kind="simulation", seed_inputs=str(bad))
    with pytest.raises(ValueError, match="an input schedule drives a simulation seed"):
        saltus.optimize(problem, seed_kind="null", seed_inputs=str(bad))
