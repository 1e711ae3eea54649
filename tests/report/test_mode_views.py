"""The animated 3-D mode views of the HTML pages (pcbdyn.report.view3d, templates/view3d.js with the
plotly.js of the plotly wheel) in headless Chromium with the network blocked (tests/browser.py): on the
build pages of the example box and card the view is drawn with the structure's parts, fixtures, ribs and
masses, it moves (two screenshots apart in time differ; paused, they do not), its colours carry the sign
of the motion, the mode picker lists every mode, and the page asks nothing of the network; on the
correlate page test and model move side by side, in phase."""

import base64
import io
import json
import time
from pathlib import Path

import numpy as np
import pytest
from browser import chromium, requests_made
from click.testing import CliRunner

from pcbdyn.cli import main

#: the module's fixtures are made once: its tests run on one xdist worker
pytestmark = pytest.mark.xdist_group("mode_views")

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def browser():
    with chromium() as driver:
        yield driver


def build(example: str, out: Path, *extra) -> dict:
    js = out.parent / f"{out.name}.json"
    res = CliRunner().invoke(main, ["build", str(ROOT / "examples" / example), "--out", str(out), "--html",
                                    "--json", str(js), *map(str, extra)])
    assert res.exit_code == 0, res.output
    return json.loads(js.read_text())


def pixels(png: bytes) -> np.ndarray:
    import matplotlib.image

    return matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3]


def open_view(browser, page: Path, frames: int = 3):
    """Load ``page``, wait for ``frames`` frames of its first view; return the view's element."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    browser.get(page.resolve().as_uri())
    view = browser.find_element(By.CSS_SELECTOR, ".view3d")
    browser.execute_script("arguments[0].scrollIntoView()", view)  # a view out of sight does not draw
    WebDriverWait(browser, 60).until(lambda d: int(view.get_attribute("data-frames") or 0) >= frames)
    return view


def drawn(browser, view) -> dict:
    """What the view's plot holds now: trace names, the surface's colours, the phase, the mode options."""
    return browser.execute_script("""
        const v = arguments[0], plot = v.querySelector('.plot'), mesh = plot.data.find(t => t.type === 'mesh3d');
        return {names: plot.data.map(t => t.name).filter(n => n), phase: parseFloat(v.dataset.phase),
                lo: Math.min(...mesh.intensity), hi: Math.max(...mesh.intensity),
                options: Array.from(v.querySelectorAll('select.mode option')).map(o => o.textContent),
                canvases: plot.querySelectorAll('canvas').length, frames: parseInt(v.dataset.frames)};""", view)


def shot(browser, view) -> np.ndarray:
    """The view's pixels, cut from a screenshot of the window (quicker than an element's screenshot)."""
    r = browser.execute_script("return arguments[0].getBoundingClientRect().toJSON()", view)
    top, left = max(int(r["top"]), 0), max(int(r["left"]), 0)
    return pixels(browser.get_screenshot_as_png())[top:int(r["bottom"]), left:int(r["right"])]


def moves(browser, view, tries: int = 4) -> float:
    """The largest share of the view's pixels that differ between two screenshots 0.3 s apart, over
    ``tries`` pairs (two instants of one cycle can show the same shape: cos a = cos -a)."""
    most = 0.0
    for _ in range(tries):
        a = shot(browser, view)
        time.sleep(0.3)
        b = shot(browser, view)
        assert a.shape == b.shape and a.size > 100_000
        most = max(most, float(np.mean(np.abs(a - b).max(axis=2) > 0.05)))
        if most > 0.002:
            break
    return most


def frames(view) -> int:
    return int(view.get_attribute("data-frames"))


def check_animates(browser, view) -> None:
    before = frames(view)
    assert moves(browser, view) > 0.002  # the shape moves
    assert frames(view) > before
    view.find_element("css selector", "button.pause").click()
    settled, last = time.monotonic(), frames(view)
    while time.monotonic() - settled < 1.0:  # the frame drawn when pause was pressed may still be on its way
        time.sleep(0.2)
        if frames(view) != last:
            settled, last = time.monotonic(), frames(view)
    assert moves(browser, view, tries=1) == 0.0  # paused: still (the difference above is the animation's)
    view.find_element("css selector", "button.pause").click()


def test_box_build_page_animates_its_modes(browser, tmp_path):
    data = build("ribbed_box/box.toml", tmp_path / "out", "--no-pictures")
    view = open_view(browser, tmp_path / "out" / "report.html")
    state = drawn(browser, view)
    assert state["canvases"] >= 1  # plotly drew with WebGL
    assert {"beams (ribs)", "plates", "stiffeners", "fixtures", "masses"} <= set(state["names"]), state["names"]
    assert state["options"] == [f"mode {m['n']}: {m['frequency_hz']:.1f} Hz, {m['shape']}" for m in data["modes"]]
    check_animates(browser, view)
    assert requests_made(browser) == []  # nothing asked of the (blocked) network
    assert browser.execute_script("return performance.getEntriesByType('resource').length") == 0


def test_card_build_page_signed_colours_and_mode_picker(browser, tmp_path):
    data = build("six_part_card/board.toml", tmp_path / "out", "--no-pictures")
    # the card is free: its elastic modes carry no effective mass, and the page and JSON say why
    assert max(v for m in data["modes"] for v in m["effective_mass"].values()) < 1e-9
    assert "mass-orthogonal to every rigid motion" in data["effective_mass_note"]
    assert data["effective_mass_note"] in (tmp_path / "out" / "report.html").read_text()
    view = open_view(browser, tmp_path / "out" / "report.html")
    state = drawn(browser, view)
    assert {"board outline", "parts", "masses"} <= set(state["names"]), state["names"]
    assert len(state["options"]) == len(data["modes"])
    check_animates(browser, view)
    # mode 2, (0,2) nodal lines: the colours (normal displacement) take both signs, scaled by the phase
    browser.execute_script("const s = arguments[0].querySelector('select.mode'); s.value = '1';"
                           "s.dispatchEvent(new Event('change'));", view)
    time.sleep(0.5)
    for _ in range(50):
        state = drawn(browser, view)
        if abs(state["phase"]) > 0.5:
            break
        time.sleep(0.05)
    assert abs(state["phase"]) > 0.5
    assert state["lo"] < -0.2 * abs(state["phase"]) and state["hi"] > 0.2 * abs(state["phase"]), state
    assert max(-state["lo"], state["hi"]) == pytest.approx(abs(state["phase"]), rel=0.02)
    assert requests_made(browser) == []


def test_correlate_page_shows_test_and_model_moving_in_phase(browser, tmp_path):
    """Test and model side by side: both scenes carry the test points; at one instant the points' motion
    in the model scene (the model's shape there) and in the test scene (the measured shape, 2 % noise,
    turned by its modal scale factor) point the same way; turning one scene turns the other."""
    card = ROOT / "examples" / "six_part_card"
    uff = tmp_path / "t.uff"
    for args in (["simulate-test", card / "board.toml", "--points", card / "points.csv", "--excite", "135,63.57",
                  "--modes", 4, "--noise", "shape=2", "--seed", 3, "--out", uff],
                 ["correlate", card / "board.toml", uff, "--out", tmp_path / "out", "--html"]):
        res = CliRunner().invoke(main, [str(a) for a in args])
        assert res.exit_code == 0, res.output
    view = open_view(browser, tmp_path / "out" / "report.html")
    assert len(drawn(browser, view)["options"]) == 4
    check_animates(browser, view)
    for _ in range(50):
        now = browser.execute_script("""
            const v = arguments[0], plot = v.querySelector('.plot');
            return {phase: parseFloat(v.dataset.phase), scenes: plot.data.filter(t => t.name === 'test points')
                    .map(t => [t.scene, t.z])};""", view)
        if abs(now["phase"]) > 0.5:
            break
        time.sleep(0.05)
    (s1, z_model), (s2, z_test) = now["scenes"]
    assert (s1, s2) == ("scene", "scene2")
    payload = json.loads(browser.execute_script("return arguments[0].querySelector('script.view-data').textContent",
                                                view))
    rest = np.frombuffer(base64.b64decode(payload["scenes"][0]["points"]), np.float32).reshape(-1, 3)
    dm, dt = np.asarray(z_model) - rest[:, 2], np.asarray(z_test) - rest[:, 2]
    assert dm @ dt / (np.linalg.norm(dm) * np.linalg.norm(dt)) > 0.95  # in phase (MAC ~ 1, same sign)
    eye = browser.execute_async_script("""  // turning the model turns the test with it
        const done = arguments[arguments.length - 1], plot = arguments[0].querySelector('.plot');
        Plotly.relayout(plot, {'scene.camera': {eye: {x: 2, y: 0.5, z: 0.3}}})
          .then(() => setTimeout(() => done(plot.layout.scene2.camera.eye), 500));""", view)
    assert eye == pytest.approx({"x": 2, "y": 0.5, "z": 0.3})
    assert requests_made(browser) == []
