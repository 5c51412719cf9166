"""The Python module cps (demos/python/cps_module.cpp): the API, the same physics as the command,
bad inputs raising ValueError or OSError and never crashing, pictures as numpy arrays.

Run by ctest through tests/python/run.sh with the module's folder on PYTHONPATH; CPS_EXE is the
cps command to compare with.
"""
import json
import math
import os
import subprocess

import numpy as np
import pytest

import cps

CPS_EXE = os.environ.get("CPS_EXE", "")


def simulate_hash(scene, seconds, *flags):
    out = subprocess.run([CPS_EXE, "simulate", scene, "--seconds", str(seconds), "--json", *flags],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)["state_hash"]


def test_scenes_and_parameters_list_what_the_command_lists():
    names = {s["name"] for s in cps.scenes()}
    assert {"stack", "intersecting_stack", "funnel", "pendulum_grid", "pendulum_wave"} <= names
    assert {"paper", "stress", "example"} <= {s["group"] for s in cps.scenes()}
    keys = {p["json_key"] for p in cps.parameters()}
    assert {"dt_s", "push", "warm_start", "friction"} <= keys
    push = next(p for p in cps.parameters() if p["name"] == "push")
    assert "split" in push["choices"] and push["default"] == "baumgarte"


@pytest.mark.parametrize("scene", ["stack", "intersecting_stack", "funnel", "pendulum_grid", "pendulum_wave"])
def test_each_paper_scene_steps_to_the_commands_state_hash(scene):
    # 2 s of each paper scene, from Python and from `cps simulate`: the same bits.
    if not CPS_EXE:
        pytest.skip("CPS_EXE is not set")
    run = cps.Run(scene)
    run.advance_to(2)
    assert run.time == pytest.approx(2.0, abs=0.5 * 1 / 60)
    assert run.state_hash() == simulate_hash(scene, 2)


def test_keywords_set_world_parameters_by_name_and_json_key():
    if not CPS_EXE:
        pytest.skip("CPS_EXE is not set")
    run = cps.Run("stack", push="split", warm_start=0.8, dt=1 / 120)
    run.advance_to(1)
    assert run.state_hash() == simulate_hash("stack", 1, "--push", "split", "--warm-start", "0.8",
                                             "--dt", "1/120")
    assert cps.Run("stack", dt_s=1 / 120).metrics()["simulated_s"] == 0.0


def test_state_shapes_units_and_a_falling_cube():
    run = cps.Run("stack")
    s = run.state()
    n = len(s["names"])
    assert s["positions"].shape == (n, 3) and s["orientations"].shape == (n, 4)
    assert s["linear_velocities"].shape == (n, 3) and s["angular_velocities"].shape == (n, 3)
    assert s["masses"].shape == (n,) and s["static"].dtype == bool
    np.testing.assert_allclose(np.linalg.norm(s["orientations"], axis=1), 1.0, atol=1e-12)
    # The top cube falls freely at first: after 0.1 s (6 steps of 1/60 s, symplectic Euler),
    # v = -g t exactly and the drop is g dt^2 (1 + ... + 6) = 21 g dt^2.
    top = int(np.argmax(s["positions"][:, 1]))
    y0 = s["positions"][top, 1]
    run.step(6)
    s = run.state()
    assert s["linear_velocities"][top, 1] == pytest.approx(-10.0 * 0.1, rel=1e-12)
    assert y0 - s["positions"][top, 1] == pytest.approx(21 * 10.0 / 3600, rel=1e-12)


def test_set_state_round_trips_and_moves_a_body():
    run = cps.Run("stack")
    run.advance_to(0.5)
    before = run.state()
    hash_before = run.state_hash()
    run.set_state(before)
    # Positions and orientations round-trip to the bit; velocities through p = m v within
    # round-off.
    after = run.state()
    np.testing.assert_array_equal(after["positions"], before["positions"])
    np.testing.assert_array_equal(after["orientations"], before["orientations"])
    np.testing.assert_allclose(after["linear_velocities"], before["linear_velocities"], rtol=1e-14, atol=1e-300)
    np.testing.assert_allclose(after["angular_velocities"], before["angular_velocities"], rtol=1e-12, atol=1e-14)
    assert len(hash_before) == 16
    lifted = run.state()
    top = int(np.argmax(lifted["positions"][:, 1]))
    lifted["positions"][top, 1] += 5.0
    lifted["linear_velocities"][top] = 0.0
    run.set_state(lifted)
    assert run.state()["positions"][top, 1] == pytest.approx(before["positions"][top, 1] + 5.0)
    run.step()
    assert run.state()["linear_velocities"][top, 1] == pytest.approx(-10.0 / 60, rel=1e-12)


def test_contacts_of_a_resting_column_carry_its_weight():
    run = cps.Run("stack")
    run.advance_to(4)
    c = run.contacts()
    k = len(c["depths"])
    assert k > 0 and c["points"].shape == (k, 3) and c["normals"].shape == (k, 3)
    np.testing.assert_allclose(np.linalg.norm(c["normals"], axis=1), 1.0, atol=1e-9)
    s = run.state()
    ground = s["static"][c["body_a"]]
    weight = float(np.sum(s["masses"])) * 10.0
    # The ground's contact rows hold the column: lambda (N) summed over them is its weight
    # within the push's share at rest (5 %).
    assert np.sum(c["lambda"][ground]) == pytest.approx(weight, rel=0.05)


def test_metrics_are_what_simulate_json_gives():
    run = cps.Run("intersecting_stack")
    run.advance_to(1)
    m = run.metrics()
    assert m["scene"] == "intersecting_stack" and m["steps"] == 60
    assert m["state_hash"] == run.state_hash()
    assert "recovery_time_s" in json.dumps(m["metrics"])


def test_render_gives_an_rgb_array_that_shows_the_bodies():
    run = cps.Run("stack")
    image = run.render(size=(160, 90))
    assert image.shape == (90, 160, 3) and image.dtype == np.uint8
    # The sky (0.86, 0.90, 0.95) and grey ground are nearly colourless; the palette's cubes are
    # not: some pixels are saturated.
    spread = image.max(axis=2).astype(int) - image.min(axis=2).astype(int)
    assert np.count_nonzero(spread > 60) > 50
    # Another camera, another picture; the same one twice, the same picture.
    assert not np.array_equal(image, run.render(size=(160, 90), camera="top"))
    np.testing.assert_array_equal(image, run.render(size=(160, 90)))


def test_a_scene_file_by_path_and_its_body_names(tmp_path):
    path = tmp_path / "drop.json"
    path.write_text(json.dumps({"bodies": [
        {"shape": "plane", "static": True, "normal": [0, 1, 0], "offset_m": 0},
        {"name": "ball", "shape": "sphere", "radius_m": 0.5, "mass_kg": 2, "position_m": [0, 3, 0]}]}))
    run = cps.Run(str(path))
    assert run.state()["names"] == ["", "ball"]
    assert run.state()["masses"][1] == 2.0
    image = run.render(size=(64, 36), camera="track:ball")
    assert image.shape == (36, 64, 3)


@pytest.mark.parametrize("scene, kwargs, says", [
    ("stak", {}, "did you mean"),
    ("all", {}, "one scene"),
    ("stack", {"pushh": "split"}, "did you mean 'push'"),
    ("stack", {"push": "splitt"}, "split"),
    ("stack", {"dt": -1.0}, "dt"),
    ("stack", {"dt": float("nan")}, "dt"),
    ("stack", {"iterations": 2.5}, "iterations"),
    ("stack", {"warm_start": "lots"}, "warm_start"),
    ("stack", {"gravity_mps2": [0, -10]}, "gravity"),
    ("stack", {"push": None}, "push"),
])
def test_bad_inputs_raise_value_error_with_the_commands_message(scene, kwargs, says):
    with pytest.raises(ValueError) as e:
        cps.Run(scene, **kwargs)
    assert says in str(e.value)


def test_a_missing_scene_file_raises_os_error(tmp_path):
    with pytest.raises(OSError):
        cps.Run(str(tmp_path / "none.json"))
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json")
    with pytest.raises(ValueError):
        cps.Run(str(bad))


def test_hostile_calls_raise_and_leave_the_run_usable():
    run = cps.Run("stack")
    for call in (lambda: run.step(-1), lambda: run.step(10**12), lambda: run.advance_to(float("nan")),
                 lambda: run.advance_to(1e30), lambda: run.render(size=(0, 10)),
                 lambda: run.render(size=(100000, 10)), lambda: run.render(camera="sideways"),
                 lambda: run.render(backend="vulkan"), lambda: run.render(camera="track:99")):
        with pytest.raises(ValueError):
            call()
    s = run.state()
    for key, value in (("positions", s["positions"][:2]), ("orientations", s["orientations"] * 2),
                       ("positions", np.full_like(s["positions"], np.nan)),
                       ("positions", "text"), ("linear_velocities", np.full_like(s["positions"], 1e300))):
        broken = dict(s)
        broken[key] = value
        with pytest.raises(ValueError):
            run.set_state(broken)
    missing = dict(s)
    del missing["orientations"]
    with pytest.raises(ValueError):
        run.set_state(missing)
    with pytest.raises(TypeError):
        run.set_state("state")
    # Nothing changed, and the run still steps.
    np.testing.assert_array_equal(run.state()["positions"], s["positions"])
    run.step()
    assert run.time == pytest.approx(1 / 60)


def test_the_worked_example_runs_and_draws_its_plot(tmp_path):
    # docs/python.md's example (demos/python/examples/warm_start_sweep.py), over 2 s: a line a
    # factor, each drift the one a direct run gives, and the PNG it names.
    pytest.importorskip("matplotlib")
    import sys
    example = os.path.join(os.path.dirname(__file__), "..", "..", "demos", "python", "examples",
                           "warm_start_sweep.py")
    out = tmp_path / "sweep.png"
    result = subprocess.run([sys.executable, example, str(out), "2"], check=True,
                            capture_output=True, text=True, env=dict(os.environ))
    lines = [l for l in result.stdout.splitlines() if l.startswith("warm_start")]
    assert len(lines) == 6
    run = cps.Run("stack", warm_start=1.0)
    start = run.state()["positions"]
    top = int(np.argmax(start[:, 1]))
    run.advance_to(2)
    moved = run.state()["positions"][top] - start[top]
    assert f"{math.hypot(moved[0], moved[2]):.4f} m" in lines[-1]
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_figure_and_render_write_what_the_command_writes(tmp_path):
    # The same figure through cps.figure and through the command: the same PNG bytes; the frames
    # of cps.render where the command puts them.
    if not CPS_EXE:
        pytest.skip("CPS_EXE is not set")
    assert cps.figure("stack", times=[0, 1], size=(160, 90), out=str(tmp_path / "py") + "/") == 0
    subprocess.run([CPS_EXE, "figure", "stack", "--times", "0,1", "--size", "160x90", "--out",
                    str(tmp_path / "cmd") + "/"], check=True, capture_output=True)
    assert (tmp_path / "py" / "stack.png").read_bytes() == (tmp_path / "cmd" / "stack.png").read_bytes()
    assert cps.render("stack", seconds=1, fps=1, size=(160, 120), out=str(tmp_path / "frames"), quiet=True) == 0
    assert sorted(p.name for p in (tmp_path / "frames" / "stack").glob("*.png")) == \
        ["frame_000000.png", "frame_000001.png"]


def test_command_keeps_the_output_rule_and_raises_the_commands_errors(tmp_path):
    # A file cps did not write is never overwritten: the call raises ValueError (exit 2) and the
    # file keeps its bytes.
    out = tmp_path / "figs"
    out.mkdir()
    (out / "stack.png").write_bytes(b"mine")
    with pytest.raises(ValueError) as e:
        cps.figure("stack", times=[0], size=(64, 36), out=str(out) + "/")
    assert "stack.png" in str(e.value)
    assert (out / "stack.png").read_bytes() == b"mine"
    with pytest.raises(ValueError) as e:
        cps.render("stack", secnds=1)
    assert "did you mean '--seconds'" in str(e.value)
    with pytest.raises(ValueError):
        cps.command([])
    assert cps.command(["list"]) == 0


def test_each_command_is_judged_on_its_own_warnings():
    # --warnings-as-errors makes the Baumgarte push's energy warning exit 3; the same run again
    # without the flag exits 0: the flag does not carry over between calls.
    args = ["simulate", "intersecting_stack", "--seconds", "0.1", "--quiet"]
    assert cps.command(args + ["--warnings-as-errors"]) == 3
    assert cps.command(args) == 0


def test_an_input_of_one_command_may_be_the_output_of_the_next(tmp_path, monkeypatch):
    # A command never writes over its own input; the inputs of an earlier call in the same
    # process are not this call's: a scene file read by simulate is then written by scene.
    monkeypatch.chdir(tmp_path)
    assert cps.command(["scene", "stack", "--out", "a.json"]) == 0
    assert cps.command(["simulate", "a.json", "--seconds", "0.1", "--quiet"]) == 0
    assert cps.command(["scene", "stack", "--out", "a.json", "--force"]) == 0
    # Within one command it still is refused: simulate's --trace onto its own scene file.
    with pytest.raises(ValueError) as e:
        cps.command(["simulate", "a.json", "--seconds", "0.1", "--trace", "a.json", "--force"])
    assert "input" in str(e.value)
