"""The studio's page in a real browser: Debian's chromium, headless, driven by
chromium-driver through selenium. The studio runs as `morphoflow studio`;
what the page does is checked against the server's own API (/api/state,
/api/scene, /api/field as .npy).

With MORPHOFLOW_SCREENSHOTS=DIR the tests also save the pictures that
docs/studio.md shows."""

import io
import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
import tomllib
import urllib.request

import numpy as np
import pytest
from selenium import webdriver
from selenium.common.exceptions import WebDriverException
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select

EXE = os.environ["MORPHOFLOW_EXECUTABLE"]
SHOTS = os.environ.get("MORPHOFLOW_SCREENSHOTS")

SCENE_2D = """
name = "studio_page"
[grid]
resolution = [32, 32]
[domain]
size = [1.0, 1.0]
[time]
dt = 0.01
steps = 1000000
[fluid]
lid_velocity = 1.0
reynolds = 100
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
rd_time_scale = 1.0
[output]
field = "v"
video = false
"""

SCENE_3D = """
name = "studio_page_3d"
[grid]
resolution = [16, 16, 16]
[domain]
size = [1.0, 1.0, 1.0]
[time]
dt = 0.02
steps = 1000000
[fluid]
lid_velocity = 1.0
reynolds = 100
[rd]
model = "gray-scott"
resolution = [32, 32, 32]
diffusion = [2e-5, 1e-5]
[rd.parameters]
F = 0.04
k = 0.06
[rd.initial]
values = [1.0, 0.0]
square = 0.6
square_values = [0.5, 0.25]
[coupling]
rd_time_scale = 20.0
[output]
field = "v"
video = false
"""


def wait_for(check, what, seconds=20.0):
    """Polls `check` until it returns something true; fails naming `what`."""
    end = time.time() + seconds
    while True:
        try:
            value = check()
        except WebDriverException:  # (a page loading or replacing its nodes: asked again)
            value = None
        if value:
            return value
        if time.time() > end:
            pytest.fail(f"timed out waiting for {what}")
        time.sleep(0.1)


class Studio:
    """`morphoflow studio SCENE --port 0`, and its API with the printed token."""

    def __init__(self, scene_text=None):
        self.dir = tempfile.mkdtemp(prefix="morphoflow-studio-page-")
        args = [EXE, "studio", "--port", "0", "--threads", "2", "--out", os.path.join(self.dir, "render")]
        if scene_text is not None:
            path = os.path.join(self.dir, "scene.toml")
            with open(path, "w") as f:
                f.write(scene_text)
            args.insert(2, path)
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        line = self.proc.stdout.readline()
        m = re.search(r"(http://[^/]+)/\?token=([0-9a-f]+)", line)
        assert m, f"the studio printed no address: {line!r}"
        self.base, self.token = m.group(1), m.group(2)
        self.url = f"{self.base}/?token={self.token}"

    def call(self, path, body=None):
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(self.base + path, data=data, headers={"Authorization": "Bearer " + self.token})
        with urllib.request.urlopen(req, timeout=20) as r:
            return r.read()

    def state(self):
        return json.loads(self.call("/api/state"))

    def scene(self):
        return tomllib.loads(self.call("/api/scene").decode())

    def field(self, name):
        return np.load(io.BytesIO(self.call(f"/api/field?name={name}")))

    def stop(self):
        self.proc.send_signal(signal.SIGINT)
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            pytest.fail("the studio did not stop on SIGINT")
        shutil.rmtree(self.dir, ignore_errors=True)


@pytest.fixture
def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    profile = tempfile.mkdtemp(prefix="morphoflow-chromium-")
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
              "--enable-unsafe-swiftshader", "--disable-quic", "--no-first-run", "--disable-background-networking",
              "--disable-component-update",
              "--disable-sync", "--window-size=1100,760", "--user-data-dir=" + profile]:
        options.add_argument(a)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver") or "/usr/bin/chromedriver"), options=options)
    driver.set_page_load_timeout(30)
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


@pytest.fixture
def studio2d():
    s = Studio(SCENE_2D)
    yield s
    s.stop()


def no_console_errors(driver, refused=0):
    """No errors in the page's console but the `refused` answers of 400 the test asked for."""
    errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
    bad_requests = [e for e in errors if e["source"] == "network" and e["message"].endswith("400 (Bad Request)")]
    assert len(bad_requests) == refused, bad_requests
    errors = [e for e in errors if e not in bad_requests]
    assert not errors, f"the page logged errors: {errors}"


def open_page(driver, studio):
    driver.get(studio.url)
    wait_for(lambda: "step" in driver.find_element(By.ID, "info").text, "the page's first state")
    wait_for(lambda: driver.execute_script("return frame !== null"), "the first frame")


def canvas_cells(driver, n):
    """The view canvas read back at the centres of an n x n grid of cells,
    as indices into the frame's palette (nearest colour), row 0 at the bottom."""
    rgba = driver.execute_script("""
        const c = document.getElementById('view'), n = arguments[0];
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data, out = [];
        for (let j = 0; j < n; ++j) for (let i = 0; i < n; ++i) {
          const x = Math.floor((i + 0.5) * c.width / n), y = Math.floor((n - 1 - j + 0.5) * c.height / n);
          const o = 4 * (y * c.width + x);
          out.push(d[o], d[o + 1], d[o + 2]);
        }
        return out;""", n)
    palette = np.array(driver.execute_script("return Array.from(frame.palette)"), dtype=float).reshape(256, 3)
    colours = np.array(rgba, dtype=float).reshape(n * n, 3)
    index = np.argmin(((colours[:, None, :] - palette[None, :, :]) ** 2).sum(axis=2), axis=1)
    return index.reshape(n, n)


def click_at(driver, x, y):
    """A click on the view at domain point (x, y) of a unit square domain."""
    view = driver.find_element(By.ID, "view")
    w, h = view.size["width"], view.size["height"]
    ActionChains(driver).move_to_element_with_offset(view, int(x * w - w / 2), int((1 - y) * h - h / 2)) \
        .click().perform()


def choose_tool(driver, name):
    driver.find_element(By.CSS_SELECTOR, f"#tools button[data-tool='{name}']").click()


def type_into(driver, element_id, value):
    e = driver.find_element(By.ID, element_id)
    e.clear()
    e.send_keys(str(value) + Keys.TAB)


def test_the_canvas_shows_the_field_and_follows_the_run(browser, studio2d):
    open_page(browser, studio2d)
    browser.find_element(By.ID, "play").click()
    wait_for(lambda: studio2d.state()["steps"] > 200, "the run to go")
    before = canvas_cells(browser, 64)
    wait_for(lambda: studio2d.state()["steps"] > 600, "the run to go on")
    browser.find_element(By.ID, "pause").click()
    wait_for(lambda: not studio2d.state()["running"], "the pause")
    # (a step under way when the pause came still ends: the paused step is read again until the frame shows it)
    wait_for(lambda: browser.execute_script("return frame.header.step") == studio2d.state()["steps"],
             "the frame of the paused step")
    shown = canvas_cells(browser, 64)
    assert np.count_nonzero(shown != before) > 100, "the canvas did not change as the run went on"
    # What is drawn is the field: each cell's palette index is its value in the frame's range, y up.
    v = studio2d.field("v")
    lo, hi = browser.execute_script("return frame.header.range")
    expected = np.clip(np.floor((v - lo) * 255.0 / (hi - lo) + 0.5), 0, 255)
    assert np.abs(shown - expected).max() <= 2, "the canvas is not the field in its palette"
    no_console_errors(browser)


def test_a_moved_control_steers_the_run(browser, studio2d):
    open_page(browser, studio2d)
    browser.find_element(By.ID, "play").click()
    wait_for(lambda: studio2d.state()["steps"] > 50, "the run to go")
    box = browser.find_element(By.CSS_SELECTOR, "#keys div[data-key='rd.parameters.F']")
    number = box.find_element(By.CSS_SELECTOR, "input[type=number]")
    number.clear()
    number.send_keys("0.05" + Keys.TAB)
    wait_for(lambda: studio2d.state()["keys"]["rd.parameters.F"]["value"] == 0.05, "F to change in the state")
    keys = studio2d.scene()["rd"]["parameters"]["F"]["keys"]
    assert keys[0] == [0.0, 0.04] and keys[-1][1] == 0.05 and keys[-1][0] > 0.0, keys
    # A value the reader refuses shows its message beside the control, and changes nothing.
    box = browser.find_element(By.CSS_SELECTOR, "#keys div[data-key='coupling.rd_time_scale']")
    number = box.find_element(By.CSS_SELECTOR, "input[type=number]")
    number.clear()
    number.send_keys("-3" + Keys.TAB)
    wait_for(lambda: "expected a number in (0" in box.find_element(By.CLASS_NAME, "err").text, "the reader's message")
    assert studio2d.state()["keys"]["coupling.rd_time_scale"]["value"] == 1.0
    assert studio2d.state()["running"]
    no_console_errors(browser, refused=1)


def test_paint_lands_where_it_is_drawn(browser, studio2d):
    open_page(browser, studio2d)
    browser.find_element(By.ID, "step").click()
    wait_for(lambda: studio2d.state()["steps"] == 1, "one step")
    # A deposit of v = 0.9, radius 0.05, clicked at (0.7, 0.3): shown at once though paused.
    choose_tool(browser, "deposit")
    Select(browser.find_element(By.ID, "pfield")).select_by_visible_text("v")
    type_into(browser, "pvalue", 0.9)
    type_into(browser, "pradius", 0.05)
    click_at(browser, 0.7, 0.3)
    wait_for(lambda: studio2d.scene().get("deposits"), "the deposit in the scene")
    d = studio2d.scene()["deposits"][0]
    assert d["field"] == "v" and d["value"] == 0.9 and d["radius"] == 0.05
    assert abs(d["center"][0] - 0.7) < 0.01 and abs(d["center"][1] - 0.3) < 0.01, d
    v = wait_for(lambda: [f for f in [studio2d.field("v")] if f.max() > 0.85], "the deposit in the field")[0]
    j, i = np.nonzero(v > 0.85)
    centre = ((i.mean() + 0.5) / 64, (j.mean() + 0.5) / 64)  # (rows are y, upward)
    assert abs(centre[0] - 0.7) < 1.5 / 64 and abs(centre[1] - 0.3) < 1.5 / 64, centre
    assert abs(len(i) / 64 ** 2 - np.pi * 0.05 ** 2) < 0.002, len(i)
    # The canvas shows it at the place clicked: the cell there is the frame's highest.
    wait_for(lambda: canvas_cells(browser, 64)[int(0.3 * 64), int(0.7 * 64)] >= 250, "the deposit on the canvas")

    # A stroke dragged from (0.2, 0.8) to (0.5, 0.6) becomes rd.strokes with those ends.
    choose_tool(browser, "stroke")
    view = browser.find_element(By.ID, "view")
    w, h = view.size["width"], view.size["height"]
    at = lambda x, y: (int(x * w - w / 2), int((1 - y) * h - h / 2))
    chain = ActionChains(browser).move_to_element_with_offset(view, *at(0.2, 0.8)).click_and_hold()
    for k in range(1, 11):
        chain = chain.move_to_element_with_offset(view, *at(0.2 + 0.03 * k, 0.8 - 0.02 * k))
    chain.release().perform()
    stroke = wait_for(lambda: studio2d.scene()["rd"].get("strokes"), "the stroke in the scene")[0]
    points = np.array(stroke["points"])
    assert np.abs(points[0] - [0.2, 0.8]).max() < 0.01 and np.abs(points[-1] - [0.5, 0.6]).max() < 0.01, points

    # An obstacle clicked at (0.3, 0.3), then moved by a drag to (0.6, 0.7).
    choose_tool(browser, "obstacle")
    click_at(browser, 0.3, 0.3)
    wait_for(lambda: studio2d.state()["elements"], "the obstacle")
    choose_tool(browser, "move")
    ActionChains(browser).move_to_element_with_offset(view, *at(0.3, 0.3)).click_and_hold() \
        .move_to_element_with_offset(view, *at(0.45, 0.5)).move_to_element_with_offset(view, *at(0.6, 0.7)) \
        .release().perform()
    moved = lambda: [e for e in studio2d.state()["elements"] if e["active"] and abs(e["center"][0] - 0.6) < 0.01]
    wait_for(moved, "the obstacle at its new place")
    assert abs(moved()[0]["center"][1] - 0.7) < 0.01
    browser.find_element(By.ID, "step").click()
    wait_for(lambda: studio2d.field("obstacle")[int(0.7 * 32), int(0.6 * 32)] > 0.5, "the moved obstacle in the fluid")
    assert studio2d.field("obstacle")[int(0.3 * 32), int(0.3 * 32)] < 0.5
    no_console_errors(browser)


def image_of(element):
    """An element's screenshot as an RGB array (read by OpenImageIO)."""
    import OpenImageIO as oiio
    with tempfile.NamedTemporaryFile(suffix=".png") as f:
        f.write(element.screenshot_as_png)
        f.flush()
        pixels = oiio.ImageInput.open(f.name).read_image(format="uint8")
    return np.asarray(pixels)[:, :, :3].astype(int)


def test_a_3d_scene_draws_a_volume_that_orbits(browser):
    s = Studio(SCENE_3D)
    try:
        open_page(browser, s)
        assert browser.execute_script("return frame.header.dims") == [32, 32, 32]
        browser.find_element(By.ID, "play").click()
        wait_for(lambda: s.state()["steps"] > 20, "the run to go")
        browser.find_element(By.ID, "pause").click()
        time.sleep(0.5)
        view = browser.find_element(By.ID, "view")
        before = image_of(view)
        background = np.array([0.07, 0.08, 0.1]) * 255
        drawn = np.abs(before - background).max(axis=2) > 8
        assert 0.05 < drawn.mean() < 0.9, f"{drawn.mean():.3f} of the view shows the volume"
        assert len(np.unique(before[drawn].reshape(-1, 3), axis=0)) > 50, "the volume is not shaded"
        ActionChains(browser).move_to_element(view).click_and_hold().move_by_offset(120, 40).release().perform()
        after = image_of(view)
        assert np.abs(after - before).max(axis=2).astype(bool).mean() > 0.02, "orbiting did not turn the view"
        # The slice shows the layer the slider picks, as the 2D view does.
        assert browser.find_element(By.ID, "slicebar").is_displayed()
        sl = browser.find_element(By.ID, "slice")
        browser.execute_script("arguments[0].value = 16; arguments[0].dispatchEvent(new Event('input'))", sl)
        assert image_of(browser.find_element(By.ID, "slicecv")).std() > 1.0
        if SHOTS:
            browser.save_screenshot(os.path.join(SHOTS, "studio_3d.png"))
        no_console_errors(browser)
    finally:
        s.stop()


def test_without_a_scene_the_page_offers_the_shipped_ones(browser):
    s = Studio()
    try:
        browser.get(s.url)
        # Read and clicked in one script each: the page may still be replacing its address (and its nodes).
        names = wait_for(lambda: browser.execute_script(
            "return [...document.querySelectorAll('#scenes li')].map((li) => li.textContent);"), "the list of scenes")
        assert any("cavity_gray_scott" in n for n in names), names
        wait_for(lambda: browser.execute_script(
            "const li = [...document.querySelectorAll('#scenes li')]"
            ".find((li) => li.textContent.endsWith('coupled/cavity_passive.toml'));"
            "if (li) li.click(); return !!li;"), "the scene clicked")
        wait_for(lambda: "step" in browser.find_element(By.ID, "info").text, "the opened scene's state")
        assert s.state()["scene"] == "cavity_passive"
        no_console_errors(browser)
    finally:
        s.stop()


def test_the_page_needs_the_token_once(browser):
    s = Studio(SCENE_2D)
    try:
        browser.get(s.base + "/")
        assert not browser.find_elements(By.ID, "view") and "unauthorized" in browser.page_source
        browser.get_log("browser")  # (the 401s asked for)
        # Opened with the token, the page drops it from the address; a reload is let in by the page's cookie.
        open_page(browser, s)
        assert "token" not in browser.current_url
        browser.refresh()
        wait_for(lambda: "step" in browser.find_element(By.ID, "info").text, "the reloaded page's state")
        no_console_errors(browser)
    finally:
        s.stop()


@pytest.mark.skipif(not SHOTS, reason="MORPHOFLOW_SCREENSHOTS names no folder")
def test_picture_of_a_shipped_scene_being_painted(browser):
    """docs/images/studio_2d.png: the shipped Gray-Scott cavity, a stroke painted into it."""
    scene = os.path.join(os.path.dirname(__file__), "..", "..", "scenes", "coupled", "cavity_gray_scott.toml")
    s = Studio(open(scene).read())
    try:
        open_page(browser, s)
        browser.find_element(By.ID, "play").click()
        wait_for(lambda: s.state()["t"] > 6.0, "the pattern to form", 120)
        choose_tool(browser, "stroke")
        view = browser.find_element(By.ID, "view")
        w, h = view.size["width"], view.size["height"]
        chain = ActionChains(browser).move_to_element_with_offset(view, int(-0.3 * w), int(0.25 * h)).click_and_hold()
        for k in range(1, 16):
            chain = chain.move_to_element_with_offset(view, int((-0.3 + 0.04 * k) * w), int((0.25 - 0.02 * k) * h))
        chain.release().perform()
        wait_for(lambda: s.scene()["rd"].get("strokes"), "the stroke")
        time.sleep(3)
        browser.save_screenshot(os.path.join(SHOTS, "studio_2d.png"))
    finally:
        s.stop()
