"""The Python module nhi against the runner `nhi run` (python/nhi_module.cpp).

Run by ctest (tests/CMakeLists.txt) with PYTHONPATH at the built module,
NHI_BINARY the runner and NHI_SCENES the scene directory.
"""
import json
import os
import subprocess
import threading
import time

import numpy as np
import pytest

import nhi

NHI_BINARY = os.environ["NHI_BINARY"]
SCENES = os.environ["NHI_SCENES"]

ARRAYS_1D = ("t", "energy")
ARRAYS_2D = ("q", "v", "constraint", "p", "lambda", "discrete_constraint")


def load_scene(name):
    with open(os.path.join(SCENES, name)) as f:
        return json.load(f)


def write_scene(tmp_path, scene):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    return str(path)


def cli_run(tmp_path, scene):
    """`nhi run` on the scene: (exit code, result or None, standard error)."""
    out = tmp_path / "result.json"
    proc = subprocess.run([NHI_BINARY, "run", write_scene(tmp_path, scene), "-o", str(out)],
                          capture_output=True, text=True)
    result = json.loads(out.read_text()) if out.exists() else None
    return proc.returncode, result, proc.stderr


def assert_same_result(py, cli):
    """Every number of the two results equal bit for bit, but for the
    per-run stats and the time in meta."""
    assert py["status"] == cli["status"]
    assert py["scene"] == cli["scene"]
    assert py["summary"] == cli["summary"]
    assert py.get("failure") == cli.get("failure")
    for key in ARRAYS_1D + ARRAYS_2D:
        assert (key in py) == (key in cli), key
        if key not in cli:
            continue
        assert py[key].dtype == np.float64
        if len(cli[key]) == 0:  # no point recorded: rows of the system's width
            assert py[key].shape[0] == 0, key
            continue
        expected = np.array(cli[key], dtype=float)
        assert py[key].shape == expected.shape, key
        # Bit for bit: the same doubles, compared as integers.
        assert np.array_equal(py[key].view(np.int64), expected.view(np.int64)), key
    assert set(py["stats"]) == set(cli["stats"])
    assert {k: v for k, v in py["meta"].items() if k != "time_utc"} == \
           {k: v for k, v in cli["meta"].items() if k != "time_utc"}


@pytest.mark.parametrize("scene_file, overrides", [
    ("particle.json", {}),
    ("particle.json", {"method": "mp06"}),
    ("particle.json", {"method": "mp06", "composition": "triple_jump"}),
    ("particle.json", {"method": "rk4"}),
    ("particle.json", {"method": "benchmark"}),
    ("particle_fig12.json", {}),
    ("contact_oscillator.json", {"method": "spark", "stages": 3, "steps": 200}),
])
def test_run_is_nhi_run_bit_for_bit(tmp_path, scene_file, overrides):
    scene = {**load_scene(scene_file), **overrides}
    code, cli, err = cli_run(tmp_path, scene)
    assert code == 0, err
    assert_same_result(nhi.run(scene), cli)


def test_first_integrals_are_arrays_by_name(tmp_path):
    scene = {**load_scene("contact_oscillator.json"), "method": "mp06", "steps": 100}
    code, cli, err = cli_run(tmp_path, scene)
    assert code == 0, err
    py = nhi.run(scene)
    assert set(py["first_integrals"]) == set(cli["first_integrals"])
    for name, series in cli["first_integrals"].items():
        assert np.array_equal(py["first_integrals"][name], np.array(series))


def test_shapes_follow_the_system():
    r = nhi.run({**load_scene("robot.json"), "steps": 10, "output_every": 3})
    n, m = len(r["scene"]["q0"]), 2
    assert r["t"].shape == (5,)  # points 0, 3, 6, 9 and the last
    assert r["q"].shape == (5, n) and r["v"].shape == (5, n)
    assert r["constraint"].shape == (5, m)
    assert r["summary"]["points"] == 5


@pytest.mark.parametrize("bad", [
    {"alpha": 1.5},
    {"method": "euler"},
    {"h": -0.1},
    {"steps": 0},
    {"q0": [1.0, 0.5]},
    {"v0": [1.0, 1.0, 1.0]},
    {"params": {"kx": 1.0, "spring": 2.0}},
    {"wobble": 1},
    {"h": "0.2"},
])
def test_bad_scene_raises_value_error_with_the_runners_message(tmp_path, bad):
    scene = {**load_scene("particle.json"), **bad}
    code, _, err = cli_run(tmp_path, scene)
    assert code == 2
    assert err.startswith("nhi: error: ")
    with pytest.raises(ValueError) as e:
        nhi.run(scene)
    assert str(e.value) == err[len("nhi: error: "):].rstrip("\n")


def test_missing_key_and_values_that_are_not_json_raise_value_error():
    scene = load_scene("particle.json")
    del scene["h"]
    with pytest.raises(ValueError, match="scene key 'h': missing"):
        nhi.run(scene)
    with pytest.raises(ValueError, match="'set' is not JSON"):
        nhi.run({**load_scene("particle.json"), "q0": {1.0, 0.5, 0.0}})
    with pytest.raises(ValueError, match="dict key must be a str"):
        nhi.run({**load_scene("particle.json"), "params": {1: 2.0}})
    with pytest.raises(ValueError, match="must be a JSON object"):
        nhi.run([1, 2, 3])
    deep = [0.0]
    for _ in range(100):
        deep = [deep]
    with pytest.raises(ValueError, match="nested deeper than 64"):
        nhi.run({**load_scene("particle.json"), "q0": deep})


def test_numpy_values_are_accepted():
    scene = load_scene("particle.json")
    as_numpy = {**scene, "q0": np.array(scene["q0"]), "h": np.float64(scene["h"]), "steps": np.int64(50)}
    plain = {**scene, "steps": 50}
    assert np.array_equal(nhi.run(as_numpy)["q"], nhi.run(plain)["q"])


def test_a_failed_run_is_a_result_not_an_exception(tmp_path):
    scene = {**load_scene("particle.json"), "tolerance": 1e-30}
    code, cli, _ = cli_run(tmp_path, scene)
    assert code == 3
    py = nhi.run(scene)
    assert py["status"] == "failed"
    assert py["failure"]["step"] == 1 and "did not converge" in py["failure"]["reason"]
    assert py["q"].shape == (0, 3) and py["constraint"].shape == (0, 1)
    assert_same_result(py, cli)


def test_lists_are_those_of_nhi_list(tmp_path):
    listed = json.loads(subprocess.run([NHI_BINARY, "list", "--json"], capture_output=True, text=True,
                                       check=True).stdout)
    assert nhi.systems() == listed["systems"]
    assert nhi.methods() == listed["methods"]
    assert nhi.compositions() == listed["compositions"]
    particle = next(s for s in nhi.systems() if s["name"] == "particle")
    assert particle["params"] == {"kx": 1.0, "ky": 1.0}
    assert {m["method"] for m in nhi.methods()} >= {"dla", "rk4", "benchmark", "mp06", "discrete_gradient", "spark",
                                                    "rkf78", "dopri5"}


def test_scene_defaults_are_what_a_run_fills_in():
    # README "Scene format": the defaults of the optional keys.
    defaults = nhi.scene_defaults()
    assert defaults == {"discretization": "alpha", "alpha": 0.5, "stages": 2, "constraint": "midpoint",
                        "composition": "none", "start": "predictor", "tolerance": 1e-12, "output_every": 1,
                        "energy_limit": "auto"}
    scene = {k: v for k, v in load_scene("particle.json").items() if k in ("system", "q0", "v0", "method", "h")}
    resolved = nhi.run({**scene, "steps": 3})["scene"]
    assert {k: resolved[k] for k in defaults} == defaults


def test_the_gil_is_released_during_a_run():
    # While one thread is inside nhi.run, another runs Python code: it records
    # clock readings inside the middle half of the run.  With the GIL held
    # through the run there can be none, however fast or slow the machine.
    scene = {**load_scene("particle.json"), "method": "benchmark", "steps": 10000, "output_every": 10000}
    span = {}

    def runner():
        span["start"] = time.perf_counter()
        nhi.run(scene)
        span["end"] = time.perf_counter()

    thread = threading.Thread(target=runner)
    readings = []
    thread.start()
    while thread.is_alive():
        readings.append(time.perf_counter())
    thread.join()
    start, end = span["start"], span["end"]
    middle = [r for r in readings if start + 0.25 * (end - start) < r < end - 0.25 * (end - start)]
    assert middle, f"no Python code ran during the {end - start:.3f} s run"


def test_runs_in_threads_at_once_are_the_runs_alone():
    scenes = [{**load_scene("particle.json"), "method": m, "steps": 2000} for m in ("dla", "mp06", "rk4", "benchmark")]
    alone = [nhi.run(s) for s in scenes]
    together = [None] * len(scenes)

    def runner(i):
        together[i] = nhi.run(scenes[i])

    threads = [threading.Thread(target=runner, args=(i,)) for i in range(len(scenes))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(alone, together):
        for key in ("t", "q", "v", "energy", "constraint"):
            assert np.array_equal(a[key], b[key]), key


def test_a_blown_up_run_fails_and_the_pairs_run():
    # README "Running a scene": |E - E0| past max(|E0|, 1) ends the run failed;
    # rkf78 and dopri5 run at their tolerance, the output grid exact.
    scene = load_scene("particle.json")
    blown = nhi.run({**scene, "method": "mp06", "h": 3, "steps": 100})
    assert blown["status"] == "failed" and blown["failure"]["kind"] == "energy"
    assert len(blown["t"]) == blown["failure"]["step"]
    for method in ("rkf78", "dopri5"):
        r = nhi.run({**scene, "method": method, "tolerance": 1e-9, "h": 0.5, "steps": 8})
        assert r["status"] == "ok"
        assert list(r["t"]) == [0.5 * k for k in range(9)]
        assert r["stats"]["internal_steps"] > 8

