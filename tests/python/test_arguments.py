"""Python checks what the command line checks (docs/python.md, "Errors"):
batch and sweep's jobs and out, override keys and values that cannot reach
another key, Ctrl-C during a batch."""
import json
import os
import signal
import threading
from pathlib import Path

import pytest

import morphoflow

SOURCE = Path(os.environ["MORPHOFLOW_SOURCE_DIR"])
PEARSON = str(SOURCE / "scenes/rd/gray_scott_pearson.toml")


@pytest.mark.parametrize("jobs", [0, -3, 257])
def test_jobs_out_of_the_command_lines_range_is_a_value_error(tmp_path, jobs):
    with pytest.raises(ValueError, match=r"jobs must be in \[1, 256\]"):
        morphoflow.batch([PEARSON], out=str(tmp_path / "b"), jobs=jobs)
    with pytest.raises(ValueError, match=r"jobs must be in \[1, 256\]"):
        morphoflow.sweep(PEARSON, ["rd.parameters.F=[0.03,0.04]"], out=str(tmp_path / "s"), jobs=jobs)
    assert not (tmp_path / "b").exists() and not (tmp_path / "s").exists()


def test_an_empty_out_is_a_value_error():
    with pytest.raises(ValueError, match="out must name a folder"):
        morphoflow.batch([PEARSON], out="")


@pytest.mark.parametrize("key",
                         ["fluid.reynolds=5", "rd.parameters.F\nfluid.reynolds", "a b", "", ".rd", "rd..F", "rd.F]"])
def test_a_key_that_could_set_another_is_refused(key):
    with pytest.raises(ValueError, match="set= takes dotted keys"):
        morphoflow.load_scene(PEARSON, set={key: 1})


@pytest.mark.parametrize("value", ['v"\nrd.parameters.F = 0.09\nx = "', "v\nrd.parameters.F = 0.09",
                                   'v\\" rd.parameters.F = 0.09', "v\x00"])
def test_a_string_value_stays_in_its_key(value):
    # Whatever the string holds, it is output.field's value: refused as a field name, never another key.
    with pytest.raises(ValueError, match="output.field"):
        morphoflow.load_scene(PEARSON, set={"output.field": value})


def test_ctrl_c_during_a_batch_raises_keyboard_interrupt_and_the_module_goes_on(tmp_path):
    long = {"grid.resolution": [128, 128], "time.steps": 20000, "output.every": 500, "output.video": False}
    timer = threading.Timer(2.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt, match="resume=True"):
        morphoflow.batch([PEARSON], out=str(tmp_path / "b"), set=long)
    timer.cancel()
    short = dict(long, **{"time.steps": 200, "output.every": 100})
    assert morphoflow.batch([PEARSON], out=str(tmp_path / "c"), set=short)["status"] == 0


def test_a_run_that_diverges_is_a_floating_point_error_as_a_diverging_step_is(tmp_path):
    diverging = {"grid.resolution": [32, 32], "rd.integrator": "explicit", "time.dt": 50.0, "time.steps": 60}
    scene = morphoflow.load_scene(PEARSON, set=diverging)
    with pytest.raises(FloatingPointError, match="diverged"):
        morphoflow.Simulation(scene).step(60)
    with pytest.raises(FloatingPointError, match="diverged"):
        morphoflow.Simulation(scene).run(str(tmp_path / "out"))
    assert json.loads((tmp_path / "out" / "run.json").read_text())["exit_state"] == "diverged"
