"""morphoflow.studio(): the studio served from Python, while Python goes on
(docs/python.md). What the page does in a browser is tests/browser's."""
import json
import os
import time
import urllib.error
import urllib.request
from pathlib import Path

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
