"""Scenes, the stepper and saltus.simulate from Python: Newton's rebound apex and impulse (the C++
tests' figures), a control loop closed in Python holding the ball at a height, the saved trajectory
the numbers of `saltus simulate`'s, and bad input as ValueError."""
import subprocess

import numpy as np
import pytest

import saltus


def test_ball_rebounds_to_newtons_apex_with_arrays_of_one_row_per_sample():
    r = saltus.simulate("ball_drop", dt=1e-4, duration=0.8, theta=0.5, set={"restitution": 0.5})
    assert r.t.shape == (8001,) and r.q.shape == (8001, 1) and r.v.shape == (8001, 1)
    assert r.q.dtype == np.float64
    assert r.coordinate_names == ["z"]
    apex = r.q[r.t > 0.5, 0].max()
    assert apex == pytest.approx(0.25, abs=2e-3)  # e² h
    scene = saltus.load_scene("ball_drop", {"restitution": 0.5})
    m = saltus.Model.from_scene("ball_drop").total_mass
    impulse = r.contacts[scene.contact_names[0]]["pn"][r.t < 0.6].sum()
    assert impulse == pytest.approx(m * 1.5 * np.sqrt(2 * 9.81), abs=2e-2)
    assert r.energy_end / r.energy_start == pytest.approx(0.25, abs=1e-2)
    assert r.stats["steps"] == 8000


def test_a_control_loop_closed_in_python_holds_the_ball():
    scene = saltus.load_scene("ball_drop")
    m = saltus.Model.from_scene("ball_drop").total_mass
    stepper = saltus.Stepper(scene, dt=1e-3)
    del scene  # the stepper keeps what it needs
    for _ in range(3000):
        z, v = stepper.q[0], stepper.v[0]
        stepper.set_input(np.array([m * 9.81 + m * 100 * (0.5 - z) - m * 20 * v]))
        stepper.step()
    assert stepper.t == pytest.approx(3.0)
    assert stepper.q[0] == pytest.approx(0.5, abs=1e-3)
    assert stepper.contacts[stepper.scene.contact_names[0]]["gap"] > 0.4


def test_a_point_on_a_bodys_plane_reports_its_place_on_it():
    # block_on_cart: the block on the cart's top (its origin, t1 = x): s1 = block_x - cart_x.
    r = saltus.simulate("block_on_cart", dt=1e-3, duration=0.5)
    deck = r.contacts["block_on_deck"]
    np.testing.assert_allclose(deck["s1"], r.q[:, 1] - r.q[:, 0], atol=1e-12)
    assert np.all(deck["s2"] == 0) and np.ptp(deck["s1"]) > 0.1
    stepper = saltus.Stepper("block_on_cart", dt=1e-3)
    stepper.step(100)
    assert stepper.contacts["block_on_deck"]["s"][0] == pytest.approx(stepper.q[1] - stepper.q[0], abs=1e-12)


@pytest.mark.parametrize("scene", ["ball_drop", "block_slide", "pendulum_conveyor", "painleve_rod", "block_on_cart",
                                   "block_on_slab", "rocking_block", "newtons_cradle", "box_on_corners", "chain_on_stops",
                                   "fast_spin", "hyq_drop", "box_stack", "skateboard"])
def test_every_built_in_scene_saves_the_commands_trajectory(scene, tmp_path, saltus_binary):
    r = saltus.simulate(scene, dt=2e-3)
    r.save(str(tmp_path / "python.csv"))
    subprocess.run([saltus_binary, "simulate", scene, "--dt", "2e-3", "--out", str(tmp_path / "cli.csv")],
                   check=True, capture_output=True)
    # The same format and numbers; the module and the program are separate builds of the same code,
    # whose round-off may differ in the last of the twelve digits (the belt of pendulum_conveyor).
    python_lines, cli_lines = (tmp_path / "python.csv").read_text().splitlines(), (tmp_path / "cli.csv").read_text().splitlines()
    assert python_lines[0] == cli_lines[0] and len(python_lines) == len(cli_lines)
    python_values = np.loadtxt(tmp_path / "python.csv", delimiter=",", skiprows=1)
    cli_values = np.loadtxt(tmp_path / "cli.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(python_values, cli_values, rtol=1e-9, atol=1e-12)


def test_a_quaternion_base_has_seven_positions_and_six_velocities():
    r = saltus.simulate("fast_spin", dt=1e-3, duration=3.0, theta=0.5)
    assert r.q.shape == (3001, 7) and r.v.shape == (3001, 6)
    assert r.position_names[3:7] == ["base_qw", "base_qx", "base_qy", "base_qz"]
    assert r.coordinate_names[3:6] == ["base_wx", "base_wy", "base_wz"]
    np.testing.assert_allclose(np.linalg.norm(r.q[:, 3:7], axis=1), 1.0, atol=1e-14)
    flipped = np.nonzero(np.diff(np.sign(r.v[:, 4])))[0]  # the intermediate-axis flip
    assert len(flipped) == 1 and r.t[flipped[0]] == pytest.approx(2.088, abs=2e-3)


def test_bad_input_is_a_value_error_with_the_located_message():
    with pytest.raises(ValueError, match="dt"):
        saltus.simulate("ball_drop", dt=0)
    with pytest.raises(ValueError, match="theta"):
        saltus.Stepper("ball_drop", theta=0.2)
    with pytest.raises(ValueError, match="no_such_scene"):
        saltus.load_scene("no_such_scene")
    with pytest.raises(ValueError, match="nonsense"):
        saltus.simulate("ball_drop", set={"nonsense": 1})
    stepper = saltus.Stepper("ball_drop")
    with pytest.raises(ValueError):
        stepper.set_input(np.zeros(3))
    assert issubclass(saltus.SimulationError, RuntimeError)


def test_objects_outlive_what_made_them():
    import gc

    stepper = saltus.Stepper(saltus.load_scene("ball_drop", {"height": 2.0}))
    scene = stepper.scene
    gc.collect()
    stepper.step(10)
    assert scene.parameters["height"] == 2.0 and stepper.q[0] < 2.0
    model = saltus.Model.from_scene("ball_drop")
    tau = saltus.rnea(model, np.zeros(1), np.zeros(1), np.zeros(1))
    del model
    gc.collect()
    assert tau[0] == pytest.approx(9.81 * saltus.Model.from_scene("ball_drop").total_mass)


def test_every_keeps_the_commands_rows_and_the_last_step(tmp_path, saltus_binary):
    full = saltus.simulate("ball_drop", dt=1e-3, duration=0.1005)  # 101 steps (the last one shorter)
    thinned = saltus.simulate("ball_drop", dt=1e-3, duration=0.1005, every=10)
    assert thinned.t.shape == (12,)  # t = 0, steps 10, 20, ..., 100, and the last
    np.testing.assert_array_equal(thinned.t[:-1], full.t[:-1:10])
    np.testing.assert_array_equal(thinned.q[-1], full.q[-1])
    thinned.save(str(tmp_path / "python.csv"))
    subprocess.run([saltus_binary, "simulate", "ball_drop", "--dt", "1e-3", "--duration", "0.1005", "--every", "10",
                    "--out", str(tmp_path / "cli.csv")], check=True, capture_output=True)
    np.testing.assert_allclose(np.loadtxt(tmp_path / "python.csv", delimiter=",", skiprows=1),
                               np.loadtxt(tmp_path / "cli.csv", delimiter=",", skiprows=1), rtol=1e-9, atol=1e-12)
    with pytest.raises(ValueError, match="every"):
        saltus.simulate("ball_drop", every=0)
