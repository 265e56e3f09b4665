"""Scenes, the stepper and saltus.simulate from Python: Newton's rebound apex and impulse (the C++
tests' figures), a control loop closed in Python holding the ball at a height, the saved trajectory
byte-identical to `saltus simulate`'s, and bad input as ValueError."""
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


def test_saved_trajectory_is_the_commands(tmp_path, saltus_binary):
    r = saltus.simulate("block_slide", dt=2e-3)
    r.save(str(tmp_path / "python.csv"))
    subprocess.run([saltus_binary, "simulate", "block_slide", "--dt", "2e-3", "--out", str(tmp_path / "cli.csv")],
                   check=True, capture_output=True)
    assert (tmp_path / "python.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()


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
