"""examples/python/ollie_retarget.py: a point-mass Ollie (`ollie_simple`) becomes a seed of the
full-body one (`ollie`). Two point-mass motions: the saved level-board solution
(tests/data/solutions/ollie_simple_level), which legs can follow throughout, and the simulation
seed of the shipped schedule (its board stands at -1 rad in the air, the point masses up to
0.4 m apart in height: out of the legs' reach there), saved as a solution without iterations."""

import numpy as np
import pytest
import saltus

NO_ITERATIONS = dict(restarts=0, ipopt={"max_iter": "0"}, task_max_iter=0, tighten_within=0, print_level=0, hints=False)


@pytest.fixture(scope="module")
def script():
    from conftest import example
    return example("ollie_retarget")


def retarget_of(script, folder, simple_dir):
    """The point-mass solution in simple_dir (reloaded, unchanged) and its full-body seed."""
    simple = saltus.optimize("ollie_simple", seed_from=str(simple_dir), seed_scale=0, **NO_ITERATIONS)
    worst, shared = script.retarget(str(simple_dir), str(folder / "seed"))
    full = saltus.optimize("ollie", seed_from=str(folder / "seed"), seed_scale=0, **NO_ITERATIONS)
    return simple, full, worst, shared


@pytest.fixture(scope="module")
def level(tmp_path_factory, script):
    from conftest import ROOT
    return retarget_of(script, tmp_path_factory.mktemp("level"), ROOT / "tests/data/solutions/ollie_simple_level")


@pytest.fixture(scope="module")
def steep(tmp_path_factory, script):
    from conftest import ROOT
    folder = tmp_path_factory.mktemp("steep")
    simple = saltus.optimize("ollie_simple", seed_kind="simulation",
                             seed_inputs=str(ROOT / "models/problems/ollie_simple_schedule.csv"), **NO_ITERATIONS)
    simple.save(str(folder / "simple"))
    return retarget_of(script, folder, folder / "simple")


def foot(model, q, v, shank):
    """The shank tip's position and velocity (x, z) [m, m/s]."""
    tip = np.array([0.0, 0.0, -0.434])
    T = saltus.forward_kinematics(model, q)[list(model.body_names).index(shank)]
    J = saltus.point_jacobian(model, q, shank, tip)
    return (T[:3, :3] @ tip + T[:3, 3])[[0, 2]], (J @ v)[[0, 2]]


@pytest.mark.parametrize("source", ["level", "steep"])
def test_the_seed_starts_at_the_problems_state_with_the_boards_motion(source, request):
    simple, full, _, shared = request.getfixturevalue(source)
    assert shared > 5000  # h and the five shared contacts' variables
    np.testing.assert_allclose(full.t, simple.t, atol=1e-12)
    np.testing.assert_allclose(full.q[0], saltus.load_problem("ollie").scene.q0, atol=1e-9)
    np.testing.assert_allclose(full.q[:, :3], simple.q[:, :3], atol=1e-9)
    np.testing.assert_allclose(full.v[:, :3], simple.v[:, :3], atol=1e-9)


def foot_errors(simple, full, worst):
    """Per sample, how far each fitted foot is from its point mass [m]; checks on the way that
    none is further than the script reported and that a foot on its point mass (within 1 mm)
    with its knee bent moves at the point mass's velocity (a straight leg cannot move its foot
    along itself at a finite rate). Returns the errors (samples x 2) and the count so checked."""
    model = saltus.Model.from_scene("skateboard_rider")
    names = list(simple.problem.scene.coordinate_names)
    coordinates = list(model.coordinate_names)
    legs = (("shank_r", [names.index("back_x"), names.index("back_z")], coordinates.index("knee_r")),
            ("shank_l", [names.index("front_x"), names.index("front_z")], coordinates.index("knee_l")))
    errors = np.zeros((len(full.t), 2))
    rates = 0
    for k in range(len(full.t)):
        for i, (shank, cols, knee) in enumerate(legs):
            p, pdot = foot(model, full.q[k], full.v[k], shank)
            errors[k, i] = np.abs(p - simple.q[k, cols]).max()
            # A joint the script left at its stop is a bounded coordinate: Ipopt's bound_push
            # (1e-6) moves it that far inside, the foot by at most a leg's length times it.
            assert errors[k, i] <= worst + 2e-6
            if errors[k, i] < 1e-3 and full.q[k, knee] > 0.1:
                rates += 1
                target = simple.v[k, cols]
                assert np.abs(pdot - target).max() <= 0.05 * np.abs(target).max() + 0.02, (k, shank)
    return errors, rates


def test_on_a_level_board_the_feet_follow_the_point_masses_throughout(level):
    simple, full, worst, _ = level
    errors, rates = foot_errors(simple, full, worst)
    assert errors.max() < 0.07
    assert np.median(errors) < 1e-3  # most points fitted exactly; the rest within 7 cm
    assert rates >= 0.3 * errors.size


def test_on_a_steep_board_the_feet_follow_where_legs_reach(steep):
    simple, full, worst, _ = steep
    errors, rates = foot_errors(simple, full, worst)
    # On a board within 0.6 rad of level the point masses stand where the legs reach; beyond,
    # up to 0.4 m apart in height, they are out of reach of legs whose hips and knees are at
    # their stops.
    theta = simple.q[:, list(simple.problem.scene.coordinate_names).index("board_theta")]
    reachable = np.abs(theta) < 0.6
    assert reachable.mean() >= 0.25
    assert errors[reachable].max() < 5e-3
    assert errors.max() > 0.1
    assert rates >= 0.3 * len(full.t)


def test_the_seeds_inputs_are_the_riders_inverse_dynamics(script):
    """The inputs the script gives a fitted point, against forward dynamics (RBDA's articulated-
    body algorithm, a second implementation): under the inputs and the feet's forces the rider
    accelerates as fitted; with the assist at 0 (the paper's problem) its three inputs are 0 and
    the joints' torques are clipped to their limits."""
    model = saltus.Model.from_scene("skateboard_rider")
    names = list(model.coordinate_names)
    rng = np.random.default_rng(4)
    problem = saltus.load_problem("ollie", {"assist": 20})
    q = np.array(problem.scene.q0) + rng.uniform(-0.2, 0.2, len(names))
    v, a = rng.uniform(-1, 1, len(names)), rng.uniform(-2, 2, len(names))
    tips = [(shank, np.array([0.0, 0.0, -0.434])) for shank in ("shank_r", "shank_l")]
    forces = [np.array([60.0, 400.0]), np.array([-30.0, 300.0])]
    u = script.inverse_dynamics(model, problem, q, v, a, forces, tips)
    assert np.all(u > problem.input_lower) and np.all(u < problem.input_upper)
    tau = saltus.rnea(model, q, v, a)  # the board: moved as given by a force of its own
    rider = [names.index(n) for n in problem.inputs]
    tau[rider] = u
    assert len(set(rider)) == 9 and set(range(3, 12)) == set(rider)  # every rider coordinate has an input
    for (shank, tip), f in zip(tips, forces):
        tau += saltus.point_jacobian(model, q, shank, tip)[[0, 2]].T @ f
    tau[[names.index(n) for n in ("board_x", "board_z", "board_theta")]] = saltus.rnea(model, q, v, a)[:3]
    np.testing.assert_allclose(saltus.aba(model, q, v, tau), a, atol=1e-9)

    paper = saltus.load_problem("ollie")
    clipped = script.inverse_dynamics(model, paper, q, v, 50 * a, forces, tips)
    assert np.all(clipped[6:] == 0)
    assert np.all(clipped >= paper.input_lower) and np.all(clipped <= paper.input_upper)
    assert np.any(clipped == paper.input_lower) or np.any(clipped == paper.input_upper)
