"""examples/python/continuation.py: a problem solved at a sequence of one parameter's values, each
step seeded by the last one's solution; on the drop (a step of its height changes its initial
state, so a solution at one height is not one at another)."""
import json
import os

import pytest
import saltus


@pytest.fixture(scope="module")
def script():
    from conftest import example
    return example("continuation")


def summary(folder):
    with open(folder / "summary.json") as f:
        return json.load(f)


def test_each_step_is_seeded_by_the_last_and_a_rerun_keeps_them(script, tmp_path, capsys):
    out = tmp_path / "chain"
    assert script.main(["point_mass_drop", "--parameter", "height", "--values", "0.1,0.2,0.3", "--out", str(out),
                        "--feasibility-repeats", "1"]) == 0
    steps = [out / f"height_{h:g}" for h in (0.1, 0.2, 0.3)]
    for h, folder in zip((0.1, 0.2, 0.3), steps):
        s = summary(folder)
        assert s["feasible"] and s["parameters"]["height"] == pytest.approx(h)
        assert s["restarts"] == 0 and s["seed_scale"] == 0 and s["feasibility_repeats"] == 1
    assert summary(steps[0])["seed"] != "solution"  # the problem's own seed
    for previous, folder in zip(steps, steps[1:]):
        s = summary(folder)
        assert s["seed"] == "solution" and s["seed_solution"] == str(previous)
    # the last step's folder is the drop from 0.3 m: solved from it, the mass falls from 0.3 m and
    # is at rest on the ground at the end
    final = saltus.optimize("point_mass_drop", seed_from=str(steps[2]), seed_scale=0, restarts=0, set={"height": 0.3})
    assert final.feasible
    assert final.q[0, 0] == pytest.approx(0.3) and abs(final.q[-1, 0]) < 1e-6 and abs(final.v[-1, 0]) < 1e-3
    capsys.readouterr()
    before = [(folder / "variables.csv").stat().st_mtime_ns for folder in steps]
    assert script.main(["point_mass_drop", "--parameter", "height", "--values", "0.1,0.2,0.3", "--out", str(out)]) == 0
    assert capsys.readouterr().out.count(", kept") == 3
    assert [(folder / "variables.csv").stat().st_mtime_ns for folder in steps] == before


class Step:
    """A stand-in for a solve: feasible where its seed's value is within `reach` of the value."""

    def __init__(self, feasible):
        self.feasible = feasible

    def save(self, folder):
        os.makedirs(folder, exist_ok=True)
        with open(os.path.join(folder, "summary.json"), "w") as f:
            json.dump({"feasible": self.feasible}, f)


def test_a_failed_step_is_retried_from_its_end_then_halved_then_stopped(script, tmp_path):
    calls, log = [], []

    def solve(seed, value, attempt):
        calls.append((seed, value, attempt))
        start = 3.0 if seed == "start" else float(seed.rsplit("_", 1)[1]) if not seed.endswith(".unfinished") else None
        return Step(start is not None and abs(start - value) <= 0.6)

    folder_of = lambda value: str(tmp_path / f"assist_{value:g}")
    # 3 -> 2 too far (retried from its own end, failing again), halved to 2.5; 2.5 -> 2 within reach;
    # 2 -> 1 halved to 1.5; 1.5 -> 1, 1 -> 0.5; 0.5 -> 0 reached
    assert script.chain([3, 2, 1, 0], solve, folder_of, "start", 0.1, log.append) == 0
    reached = [(value, attempt) for seed, value, attempt in calls]
    assert reached == [(3, 1), (2, 1), (2, 2), (2.5, 1), (2, 1), (1, 1), (1, 2), (1.5, 1), (1, 1), (0, 1), (0, 2),
                       (0.5, 1), (0, 1)]
    assert calls[2][0] == folder_of(2) + ".unfinished"  # the retry goes on from the first attempt's end
    assert calls[4][0] == folder_of(2.5)  # each step from the last feasible one
    assert all(os.path.isfile(os.path.join(folder_of(v), "summary.json")) for v in (3, 2.5, 2, 1.5, 1, 0.5, 0))

    # a second run keeps every saved step; a step that cannot be halved any further stops the chain
    calls.clear()
    assert script.chain([3, 2, 1, 0], solve, folder_of, "start", 0.1, log.append) == 0
    assert calls == [] and sum("kept" in line for line in log[-5:]) == 4
    assert script.chain([0, -0.7], solve, folder_of, "start", 0.4, log.append) == 1
    assert [(value, attempt) for seed, value, attempt in calls] == [(-0.7, 1), (-0.7, 2)]
    assert "-0.7: not feasible" in log[-1] and not os.path.exists(folder_of(-0.7))


def test_the_inputs_use_is_read_at_the_collocation_points(script):
    from conftest import ROOT
    level = saltus.optimize("ollie_simple", seed_from=str(ROOT / "tests/data/solutions/ollie_simple_level"),
                            seed_scale=0, restarts=0, ipopt={"max_iter": "0"}, task_max_iter=0, tighten_within=0,
                            hints=False)
    inputs = list(level.problem.inputs)
    use = script.input_use(level, inputs)
    assert [name for name, _, _ in use] == inputs
    # the bounded values: within the bounds, each force at 0.9 of its bound or more somewhere
    assert all(0.9 < largest <= 1 + 1e-9 and 0 < rms < largest for _, largest, rms in use)
    # the element ends' extrapolation, left out, goes past the bounds
    assert (abs(level.u).max(axis=0) > 1.02 * abs(level.problem.input_upper)).all()


def test_a_steps_line_names_the_stage_its_status_comes_from(script):
    # feasible after the tightening stage, the task stage stopped at its cap: the status is the
    # task stage's, not the solve's verdict
    stages = [{"name": "feasibility", "iterations": 40, "status": "Solved_To_Acceptable_Level"},
              {"name": "tightening", "iterations": 5, "status": "Solve_Succeeded"},
              {"name": "task", "iterations": 300, "status": "Maximum_Iterations_Exceeded"}]

    class Solved:
        summary = {"feasible": True, "largest_product": 9e-5, "largest_violation": 2e-6, "wall_seconds": 12.0,
                   "stages": stages, "kept_stage": 2}
    line = script.describe("assist", 0.25, "seed", Solved(), 1, [])
    assert line == ("assist 0.25 (from seed, attempt 1): feasible (the task stage: Maximum_Iterations_Exceeded), "
                    "largest product 9e-05, constraints 2e-06, iterations 40 + 5 + 300, 12 s")

    # the task stage ended infeasible and the tightening stage's point is the solution: its status
    class Kept:
        summary = dict(Solved.summary, kept_stage=1)
    line = script.describe("assist", 0.25, "seed", Kept(), 1, [])
    assert "feasible (the tightening stage: Solve_Succeeded)" in line, line


def test_bad_arguments_name_what_was_expected(script, tmp_path, capsys):
    def error(*argv):
        with pytest.raises(SystemExit) as e:
            script.main(["point_mass_drop", *argv, "--out", str(tmp_path / "x")])
        assert e.value.code == 2
        return capsys.readouterr().err

    assert "--parameter mass: point_mass_drop has no such parameter (it has height, restitution)" in error(
        "--parameter", "mass", "--values", "1")
    assert "expected numbers separated by commas, got '1,a'" in error("--parameter", "height", "--values", "1,a")
    assert "expected distinct values" in error("--parameter", "height", "--values", "1,1")
    assert "--report force: point_mass_drop has no such input" in error("--parameter", "height", "--values", "1",
                                                                         "--report", "force")
    assert "expected a solution folder holding variables.csv" in error("--parameter", "height", "--values", "1",
                                                                       "--seed-from", str(tmp_path))
    assert "--feasibility-repeats: expected a count of 0 or more, got -1" in error(
        "--parameter", "height", "--values", "1", "--feasibility-repeats", "-1")
    assert not (tmp_path / "x").exists()
