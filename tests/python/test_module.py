"""The Python module (docs/python.md) against the command line and itself:
fields round-trip through numpy bit for bit, a run from Python writes the
command line's frames, a numpy velocity carries a blob as the expression
velocity does, and every misuse is a Python exception."""
import json
import os
import signal
import subprocess
from pathlib import Path

import numpy as np
import pytest

import morphoflow

SOURCE = Path(os.environ["MORPHOFLOW_SOURCE_DIR"])
EXECUTABLE = os.environ["MORPHOFLOW_EXECUTABLE"]
PEARSON = str(SOURCE / "scenes/rd/gray_scott_pearson.toml")
SMALL = {"grid.resolution": [48, 48], "time.steps": 60, "output.every": 20, "output.video": False}

ROTATION = """
name = "rotation"
[grid]
resolution = [48, 48]
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
"""


def blob(n, centre=(0.5, 0.75), sigma=0.06):
    c = (np.arange(n) + 0.5) / n
    x, y = np.meshgrid(c, c)
    return np.exp(-((x - centre[0]) ** 2 + (y - centre[1]) ** 2) / (2 * sigma**2)).astype(np.float32)


def test_a_scene_reads_with_its_overrides_and_resolved_settings():
    scene = morphoflow.load_scene(PEARSON, set={"grid.resolution": [64, 32], "domain.size": [2.5, 1.25],
                                                "rd.parameters.F": 0.03})
    assert scene.dimension == 2
    assert scene.name == "gray_scott_pearson"
    assert scene.settings["grid"]["resolution"] == [64, 32]
    sim = morphoflow.Simulation(scene)
    assert sim.field("u").shape == (32, 64)  # indexed [y, x]


def test_fields_round_trip_through_numpy_bitwise():
    sim = morphoflow.Simulation(morphoflow.load_scene(PEARSON, set=SMALL))
    sim.step(5)
    for name in ("u", "v"):
        values = sim.field(name)
        changed = (values * np.float32(0.5) + np.float32(0.25)).astype(np.float32)
        sim.set_field(name, changed)
        assert sim.field(name).tobytes() == changed.tobytes()
    fluid = morphoflow.Simulation(morphoflow.load_scene(str(SOURCE / "scenes/vfx/plume_2d.toml"),
                                                        set={"grid.resolution": [24, 36]}))
    smoke = np.linspace(0, 1, 24 * 36, dtype=np.float32).reshape(36, 24)
    fluid.set_field("dye", smoke)
    assert fluid.field("dye").tobytes() == smoke.tobytes()


def test_a_run_from_python_writes_the_command_lines_frames(tmp_path):
    sets = [f"--set={k}={json.dumps(v).lower() if isinstance(v, bool) else json.dumps(v)}" for k, v in SMALL.items()]
    subprocess.run([EXECUTABLE, "run", PEARSON, *sets, "--quiet", "--out", str(tmp_path / "cli")], check=True)
    reports = []
    sim = morphoflow.Simulation(morphoflow.load_scene(PEARSON, set=SMALL))
    run = sim.run(str(tmp_path / "py"), progress=reports.append)
    assert run["exit_state"] == "completed"
    assert reports and reports[-1]["step"] == 60
    frames = sorted((tmp_path / "cli" / "frames").iterdir())
    assert len(frames) == 4
    for f in frames:
        assert (tmp_path / "py" / "frames" / f.name).read_bytes() == f.read_bytes(), f.name


def test_a_numpy_velocity_carries_a_blob_as_the_expression_does_bitwise():
    given = morphoflow.Simulation(morphoflow.scene_from_toml(ROTATION + 'field = ["-(y - 0.5)", "x - 0.5"]\n'))
    from_python = morphoflow.Simulation(morphoflow.scene_from_toml(ROTATION + "python = true\n"))
    for sim in (given, from_python):
        sim.set_field("v", blob(48))
    from_python.set_velocity(lambda x, y, t: (-(y - 0.5), x - 0.5))
    given.step(20)
    from_python.step(20)
    assert from_python.field("v").tobytes() == given.field("v").tobytes()
    assert np.abs(given.field("v") - blob(48)).max() > 0.1  # it moved


def test_a_simulation_saves_and_loads_bit_for_bit(tmp_path):
    sim = morphoflow.Simulation(morphoflow.load_scene(PEARSON, set=SMALL))
    sim.step(10)
    sim.save(str(tmp_path / "state.ckpt"))
    again = morphoflow.Simulation.load(str(tmp_path / "state.ckpt"))
    assert again.steps == 10 and again.time == sim.time
    sim.step(10)
    again.step(10)
    assert again.field("v").tobytes() == sim.field("v").tobytes()


def test_misuse_is_a_python_exception():
    with pytest.raises(ValueError, match=r"gray_scott_pearson.toml:\d+:\d+: error: 'rd.nope'|--set rd.nope"):
        morphoflow.load_scene(PEARSON, set={"rd.nope": 1})
    with pytest.raises(ValueError, match=r"<string>:3:\d+: error: 'grid.bogus'"):
        morphoflow.scene_from_toml('name = "x"\n[grid]\nbogus = 1\n')
    sim = morphoflow.Simulation(morphoflow.load_scene(PEARSON, set=SMALL))
    good = sim.field("v")
    with pytest.raises(TypeError, match="float32"):
        sim.set_field("v", good.astype(np.float64))
    with pytest.raises(ValueError, match="shape"):
        sim.set_field("v", good[:10])
    bad = good.copy()
    bad[3, 4] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        sim.set_field("v", bad)
    with pytest.raises(ValueError, match="no field"):
        sim.field("pressure")
    with pytest.raises(ValueError, match="python = true"):
        sim.set_velocity(lambda x, y, t: (x, y))
    with pytest.raises(ValueError, match="backend"):
        morphoflow.Simulation(morphoflow.load_scene(PEARSON), backend="cuda")
    rotation = morphoflow.Simulation(morphoflow.scene_from_toml(ROTATION + "python = true\n"))
    with pytest.raises(ValueError, match="shape"):
        rotation.set_velocity(np.zeros((2, 5, 5)))
    with pytest.raises(ValueError, match="NaN"):
        rotation.set_velocity(lambda x, y, t: (x * np.nan, y))
    with pytest.raises(RuntimeError, match="boom"):
        rotation.set_velocity(lambda x, y, t: (_ for _ in ()).throw(RuntimeError("boom")))
    sim.close()
    with pytest.raises(RuntimeError, match="closed"):
        sim.step()
    with pytest.raises(RuntimeError, match="closed"):
        sim.field("v")


def test_ctrl_c_checkpoints_then_raises_keyboard_interrupt(tmp_path):
    sim = morphoflow.Simulation(morphoflow.load_scene(PEARSON, set=SMALL))

    def interrupt(report):
        if report["step"] == 30:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        sim.run(str(tmp_path / "out"), progress=interrupt)
    assert list((tmp_path / "out" / "checkpoints").iterdir())
    run = json.loads((tmp_path / "out" / "run.json").read_text())
    assert run["exit_state"] == "interrupted"
    resumed = morphoflow.Simulation(morphoflow.load_scene(PEARSON, set=SMALL)).run(str(tmp_path / "out"), resume=True)
    assert resumed["exit_state"] == "completed" and resumed["steps"] == 60


def test_batch_and_sweep_return_their_summaries(tmp_path):
    scene = str(tmp_path / "small.toml")
    Path(scene).write_text(Path(PEARSON).read_text())
    result = morphoflow.batch([scene], out=str(tmp_path / "batch"), set=SMALL)
    assert result["status"] == 0
    runs = result["summary"]["runs"]
    assert len(runs) == 1 and runs[0]["status"] == "completed"
    swept = morphoflow.sweep(scene, ["rd.parameters.F=[0.03,0.04]"], out=str(tmp_path / "sweep"), set=SMALL)
    assert swept["status"] == 0 and len(swept["summary"]["runs"]) == 2


def test_the_gpu_backend_takes_and_gives_fields_as_the_cpu():
    scene = morphoflow.load_scene(PEARSON, set={**SMALL, "gpu.precision": "double"})  # (compared to 1e-5)
    try:
        gpu = morphoflow.Simulation(scene, backend="gpu")
    except ValueError as e:
        pytest.skip(f"no GPU context: {e}")
    cpu = morphoflow.Simulation(scene, backend="tbb")
    start = blob(48)
    for sim in (gpu, cpu):
        sim.set_field("v", start)
    assert gpu.field("v").tobytes() == start.tobytes()
    gpu.step(20)
    cpu.step(20)
    assert np.abs(gpu.field("v") - cpu.field("v")).max() < 1e-5
