"""examples/python/ollie_retarget.py: a point-mass Ollie (`ollie_simple`) becomes a seed of the
full-body one (`ollie`). The point-mass motion is the simulation seed of the shipped schedule
(the time-stepper's stamp, tail strike and air phase), saved as a solution without iterations."""
import importlib.util

import numpy as np
import pytest
import saltus

NO_ITERATIONS = dict(restarts=0, ipopt={"max_iter": "0"}, task_max_iter=0, tighten_within=0, print_level=0, hints=False)


@pytest.fixture(scope="module")
def script():
    from conftest import ROOT
    spec = importlib.util.spec_from_file_location("ollie_retarget", ROOT / "examples/python/ollie_retarget.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def solutions(tmp_path_factory, script):
    from conftest import ROOT
    folder = tmp_path_factory.mktemp("retarget")
    simple = saltus.optimize("ollie_simple", seed_kind="simulation",
                             seed_inputs=str(ROOT / "models/problems/ollie_simple_schedule.csv"), **NO_ITERATIONS)
    simple.save(str(folder / "simple"))
    worst, shared = script.retarget(str(folder / "simple"), str(folder / "seed"))
    full = saltus.optimize("ollie", seed_from=str(folder / "seed"), seed_scale=0, **NO_ITERATIONS)
    return simple, full, worst, shared


def foot(model, q, v, shank):
    """The shank tip's position and velocity (x, z) [m, m/s]."""
    tip = np.array([0.0, 0.0, -0.434])
    T = saltus.forward_kinematics(model, q)[list(model.body_names).index(shank)]
    J = saltus.point_jacobian(model, q, shank, tip)
    return (T[:3, :3] @ tip + T[:3, 3])[[0, 2]], (J @ v)[[0, 2]]


def test_the_seed_starts_at_the_problems_state_with_the_boards_motion(solutions):
    simple, full, _, shared = solutions
    assert shared > 5000  # h and the five shared contacts' variables
    np.testing.assert_allclose(full.t, simple.t, atol=1e-12)
    np.testing.assert_allclose(full.q[0], saltus.load_problem("ollie").scene.q0, atol=1e-9)
    np.testing.assert_allclose(full.q[:, :3], simple.q[:, :3], atol=1e-9)
    np.testing.assert_allclose(full.v[:, :3], simple.v[:, :3], atol=1e-9)


def test_the_feet_follow_the_point_masses(solutions):
    simple, full, worst, _ = solutions
    model = saltus.Model.from_scene("skateboard_rider")
    names = list(simple.problem.scene.coordinate_names)
    back = [names.index("back_x"), names.index("back_z")]
    front = [names.index("front_x"), names.index("front_z")]
    knees = {"shank_r": list(model.coordinate_names).index("knee_r"), "shank_l": list(model.coordinate_names).index("knee_l")}
    level, rates, samples = 0, 0, len(full.t)
    for k in range(samples):
        # On a board within 0.6 rad of level the point masses stand where the legs reach (the
        # shipped schedule's board stands at -1 rad in the air, its point masses up to 0.4 m
        # apart in height, out of reach of legs whose hips and knees are at their stops).
        reachable = abs(simple.q[k, names.index("board_theta")]) < 0.6
        level += reachable
        for shank, cols in (("shank_r", back), ("shank_l", front)):
            p, pdot = foot(model, full.q[k], full.v[k], shank)
            error = np.abs(p - simple.q[k, cols]).max()
            assert error <= worst + 1e-9
            if reachable:
                assert error < 5e-3, (k, shank)
            if error < 1e-3 and full.q[k, knees[shank]] > 0.1:
                # where the foot is on its point mass and its leg bent (a straight leg cannot move
                # its foot along itself at a finite rate), it moves with the point mass
                rates += 1
                target = simple.v[k, cols]
                assert np.abs(pdot - target).max() <= 0.05 * np.abs(target).max() + 0.02, (k, shank)
    assert level >= 0.25 * samples
    assert rates >= 0.3 * samples
