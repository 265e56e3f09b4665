"""saltus.replay and saltus.render from Python: a saved drop replayed within tolerance in both engines
with the command's report files, a video and frames written, and frames in memory equal to the PNG
files of the same frames."""
import numpy as np
import pytest

import saltus


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    folder = tmp_path_factory.mktemp("drop")
    saltus.optimize("point_mass_drop", set={"restitution": 0.5}).save(str(folder))
    return folder


def test_replay_in_both_engines_writes_the_commands_report(saved, tmp_path):
    r = saltus.replay(str(saved), out=str(tmp_path / "replay"), engine="both", charts=False)
    assert r["within_tolerance"]
    assert set(r["engines"]) == {"saltus", "bullet"}
    assert r["engines"]["saltus"]["max_position_deviation"] <= r["tolerance"]
    assert r["engines"]["saltus"]["events_matched"] == r["engines"]["saltus"]["events_optimised"] > 0
    assert (tmp_path / "replay" / "replay.json").exists() and (tmp_path / "replay" / "replay.csv").exists()
    with pytest.raises(ValueError, match="engine"):
        saltus.replay(str(saved), engine="ode")


def test_render_writes_frames_and_draws_the_same_in_memory(saved, tmp_path):
    frames = saltus.render(str(saved), frames=str(tmp_path / "frames"), fps=10, width=64, height=48)
    files = sorted((tmp_path / "frames").glob("frame_*.png"))
    assert len(files) == frames > 1
    renderer = saltus.FrameRenderer(str(saved), fps=10, width=64, height=48)
    assert renderer.frames == frames
    image = renderer.draw(frames - 1)
    assert image.shape == (48, 64, 3) and image.dtype == np.uint8
    assert image.std() > 0  # not a blank frame
    with pytest.raises(IndexError):
        renderer.draw(frames)
    with pytest.raises(ValueError, match="nothing to write"):
        saltus.render(str(saved))


def test_a_solution_of_a_changed_problem_is_refused_unless_allowed(root, tmp_path):
    problem = tmp_path / "drop.yaml"
    problem.write_text((root / "models" / "problems" / "point_mass_drop.yaml").read_text())
    saltus.optimize(str(problem)).save(str(tmp_path / "sol"))
    assert saltus.replay(str(tmp_path / "sol"))["within_tolerance"]
    problem.write_text(problem.read_text().replace("mass: 1.0", "mass: 2.0"))
    with pytest.raises(ValueError, match="changed since this solution was saved.*allow_changed_problem"):
        saltus.replay(str(tmp_path / "sol"))
    with pytest.raises(ValueError, match="changed since this solution was saved"):
        saltus.render(str(tmp_path / "sol"), frames=str(tmp_path / "frames"), width=32, height=32)
    assert not (tmp_path / "frames").exists()
    assert "engines" in saltus.replay(str(tmp_path / "sol"), allow_changed_problem=True)
    with pytest.warns(UserWarning, match="changed since"):
        saltus.render(str(tmp_path / "sol"), frames=str(tmp_path / "frames"), width=32, height=32,
                      allow_changed_problem=True)
