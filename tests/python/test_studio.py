"""morphoflow.studio(): the studio served from Python, while Python goes on
(docs/python.md). What the page does in a browser is tests/browser's."""
import io
import json
import os
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

import morphoflow

SOURCE = Path(os.environ["MORPHOFLOW_SOURCE_DIR"])
CAVITY = str(SOURCE / "scenes/coupled/cavity_passive.toml")


def call(studio, path, body=None, token=True):
    headers = {"Authorization": "Bearer " + studio.token} if token else {}
    data = None if body is None else json.dumps(body).encode()
    base = studio.url.split("/?")[0]
    with urllib.request.urlopen(urllib.request.Request(base + path, data=data, headers=headers), timeout=20) as r:
        return r.status, r.read()


def test_a_studio_serves_the_scene_while_python_goes_on(tmp_path):
    with morphoflow.studio(CAVITY, out=str(tmp_path / "render")) as s:
        assert s.running and s.url.startswith(f"http://127.0.0.1:{s.port}/?token={s.token}")
        status, page = call(s, "/")
        assert status == 200 and b"morphoflow studio" in page
        with pytest.raises(urllib.error.HTTPError) as refused:
            call(s, "/api/state", token=False)
        assert refused.value.code == 401
        call(s, "/api/control", {"action": "play"})
        steps = s.state()["steps"]
        time.sleep(0.5)  # Python is free while the simulation runs on its own thread
        assert s.state()["steps"] > steps
        call(s, "/api/set", {"coupling.rd_time_scale": 2.0})
        assert s.state()["keys"]["coupling.rd_time_scale"]["value"] == 2.0
        assert "keys = [ [ 0.0" in s.scene() and s.state()["scene"] == "cavity_passive"
        port = s.port
    assert not s.running and repr(s) == "<morphoflow.Studio stopped>"
    with pytest.raises(RuntimeError, match="stopped"):
        s.url
    with pytest.raises(urllib.error.URLError):  # the port is closed
        urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=5)


def test_without_a_scene_it_offers_the_shipped_ones():
    s = morphoflow.studio()
    try:
        assert s.state() is None and s.scene() is None
        _, body = call(s, "/api/scenes")
        listing = json.loads(body)
        assert "coupled/cavity_passive.toml" in listing["scenes"] and listing["open"] is None
    finally:
        s.stop()
    s.stop()  # a second stop does nothing


def test_bad_arguments_are_python_exceptions(tmp_path):
    with pytest.raises(ValueError, match="port"):
        morphoflow.studio(CAVITY, port=70000)
    with pytest.raises(ValueError, match="backend"):
        morphoflow.studio(CAVITY, backend="quantum")
    with pytest.raises(ValueError, match="threads"):
        morphoflow.studio(CAVITY, threads=-1)
    with pytest.raises(ValueError, match="nothing.toml"):
        morphoflow.studio(str(tmp_path / "nothing.toml"))
    bad = tmp_path / "bad.toml"
    bad.write_text("[grid]\nresolution = [0, 8]\n")
    with pytest.raises(ValueError, match="bad.toml:2"):
        morphoflow.studio(str(bad))
    with morphoflow.studio(CAVITY) as s:  # a port in use is named, with what to do
        with pytest.raises(ValueError, match=f"{s.port}: Address already in use.*--port"):
            morphoflow.studio(CAVITY, port=s.port)


ROUND_TRIP = """
name = "round_trip"
[grid]
resolution = [32, 32]
[domain]
size = [1.0, 1.0]
[time]
dt = 0.01
steps = 20
[fluid]
lid_velocity = 1.0
reynolds = 400
[rd]
model = "gray-scott"
resolution = [64, 64]
diffusion = [2e-5, 1e-5]
[rd.parameters]
F = 0.04
k = 0.06
[rd.initial]
values = [1.0, 0.0]
square = 0.3
square_values = [0.5, 0.25]
[coupling]
rd_time_scale = 50.0
[output]
every = 5
field = "v"
fields = true
video = false
"""


def read_dump(path):
    """A field dump (EXR) as {channel: array[y, x]}, y up, by OpenImageIO."""
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(str(path))
    names = inp.spec().channelnames
    pixels = inp.read_image("float")
    inp.close()
    return {name: pixels[::-1, :, c] for c, name in enumerate(names)}


def test_render_runs_the_saved_scene_with_morphoflow_run_to_the_studios_fields_bitwise(tmp_path):
    """Edits of each kind, then Render: `morphoflow run` of the saved scene,
    in the background, writes at the last step the studio's fields bit for bit."""
    scene = tmp_path / "round_trip.toml"
    scene.write_text(ROUND_TRIP)
    with morphoflow.studio(str(scene), out=str(tmp_path / "render")) as s:
        def step_to(n):
            call(s, "/api/control", {"action": "step", "count": n - s.state()["steps"]})
            for _ in range(400):
                if s.state()["steps"] == n:
                    return
                time.sleep(0.01)
            raise AssertionError(f"the studio did not reach step {n}")
        step_to(4)
        call(s, "/api/set", {"rd.parameters.F": 0.05, "fluid.lid_velocity": 0.7})
        step_to(9)
        call(s, "/api/paint", {"kind": "deposit", "field": "v", "center": [0.6, 0.6], "radius": 0.1, "value": 0.4})
        call(s, "/api/paint", {"kind": "obstacle", "shape": "box", "center": [0.7, 0.3], "size": [0.1, 0.2]})
        step_to(13)
        call(s, "/api/paint",
             {"kind": "stroke", "points": [[0.2, 0.2], [0.4, 0.3]], "width": 0.03, "values": [0.5, 0.25]})
        call(s, "/api/paint", {"kind": "move", "target": "obstacles.0", "center": [0.3, 0.7]})
        step_to(20)
        fields = {name: np.load(io.BytesIO(call(s, f"/api/field?name={name}")[1])) for name in ("u", "v")}
        call(s, "/api/render", {})
        for _ in range(600):
            render = s.state()["render"]
            if not render["running"]:
                break
            time.sleep(0.1)
        out = tmp_path / "render" / "round_trip_render"  # the output folder, named in the state
        assert render["exit_code"] == 0 and render["out"] == str(out), render
        assert render["frames"] == render["total_frames"] == 5 and render["progress"] == 1.0
    assert "[[deposits]]" in (tmp_path / "render" / "round_trip_studio.toml").read_text()  # the saved scene it ran
    dump = read_dump(out / "fields" / "000004.exr")  # step 20
    for name, values in fields.items():
        assert dump[name].tobytes() == values.tobytes(), f"{name} differs from the studio's"
