"""A Simulation's lifetime and threads (docs/python.md, "Threads"): one call
at a time, a second refused with RuntimeError naming the first; close()
during a call takes effect when the call ends; nothing crashes the
interpreter or reads freed memory."""
import os
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import morphoflow

SOURCE = Path(os.environ["MORPHOFLOW_SOURCE_DIR"])
PEARSON = str(SOURCE / "scenes/rd/gray_scott_pearson.toml")
SMALL = {"grid.resolution": [48, 48], "time.steps": 60, "output.every": 20, "output.video": False,
         "gpu.precision": "double"}  # (the GPU as the CPU computes: compared to 1e-5)
FLOW = """
name = "flow"
[grid]
resolution = [32, 32]
[domain]
size = [1.0, 1.0]
[time]
dt = 0.02
steps = 40
[rd]
model = "gray-scott"
[coupling]
mode = "passive"
[velocity]
python = true
"""


def pearson(backend="tbb"):
    return morphoflow.Simulation(morphoflow.load_scene(PEARSON, set=SMALL), backend=backend)


def closed(sim):
    with pytest.raises(RuntimeError, match="closed"):
        sim.steps
    return True


def test_close_from_the_progress_callback_takes_effect_after_the_run(tmp_path):
    sim = pearson()
    seen = []

    def progress(p):
        seen.append(p["step"])
        if len(seen) == 2:
            sim.close()

    run = sim.run(str(tmp_path / "out"), progress=progress)
    assert run["steps"] == 60 and seen[-1] == 60  # the run went on to its end
    assert closed(sim)
    sim.close()  # again: nothing


def test_close_from_the_velocity_callable_takes_effect_after_the_step():
    sim = morphoflow.Simulation(morphoflow.scene_from_toml(FLOW))
    calls = []

    def velocity(x, y, t):
        if armed:
            calls.append(t)
            if len(calls) == 2:
                sim.close()
        return (-(y - 0.5), x - 0.5)

    armed = False
    sim.set_velocity(velocity)
    armed = True
    sim.step(5)
    assert len(calls) >= 2 and closed(sim)  # the step ended, then the close took effect


def test_a_call_from_a_callback_is_refused_naming_the_call_in_progress(tmp_path):
    sim = pearson()
    errors = []

    def progress(p):
        for call in (lambda: sim.step(), lambda: sim.field("v"),
                     lambda: sim.set_field("v", np.zeros((48, 48), np.float32)),
                     lambda: sim.save(str(tmp_path / "x.ckpt")), lambda: sim.steps):
            try:
                call()
            except RuntimeError as e:
                errors.append(str(e))
        raise StopIteration("enough")

    with pytest.raises(StopIteration, match="enough"):  # the callback's own exception comes out of run
        sim.run(str(tmp_path / "out"), progress=progress)
    assert len(errors) == 5 and all("this Simulation is in run()" in e for e in errors), errors
    assert sim.steps > 0  # usable after


def test_two_threads_on_one_simulation_one_call_at_a_time():
    sim = pearson()
    outcomes = []

    def stepper():
        try:
            sim.step(200)
            outcomes.append("stepped")
        except RuntimeError as e:
            outcomes.append(str(e))

    threads = [threading.Thread(target=stepper) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    stepped = outcomes.count("stepped")
    assert stepped >= 1 and all(o == "stepped" or "this Simulation is in step()" in o for o in outcomes), outcomes
    assert sim.steps == 200 * stepped  # no step was lost or taken twice
    assert np.isfinite(sim.field("v")).all()


def test_close_from_another_thread_during_step():
    sim = pearson()
    t = threading.Thread(target=lambda: sim.step(400))
    t.start()
    time.sleep(0.05)
    sim.close()  # returns at once; the step in progress finishes first
    t.join()
    assert closed(sim)


def test_gpu_simulations_on_several_threads_run_one_at_a_time_or_are_refused():
    try:
        first = pearson("gpu")
    except ValueError as e:
        pytest.skip(f"no GPU context: {e}")
    second = pearson("gpu")
    outcomes = []

    def stepper(sim):
        try:
            for _ in range(20):
                sim.step(5)
            outcomes.append("stepped")
        except RuntimeError as e:
            outcomes.append(str(e))

    threads = [threading.Thread(target=stepper, args=(s,)) for s in (first, second)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(o == "stepped" or "another thread" in o for o in outcomes), outcomes
    # One after the other, from any thread, both run; and agree with the CPU.
    for sim in (first, second):
        t = threading.Thread(target=lambda: sim.step(3))
        t.start()
        t.join()
    cpu = pearson()
    cpu.step(first.steps)
    assert np.abs(first.field("v") - cpu.field("v")).max() < 1e-5
    first.close()
    del second  # freed on this thread, the context taken for it
