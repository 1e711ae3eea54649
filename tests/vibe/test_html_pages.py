"""The HTML pages of vibe, build and correlate, opened in real headless Chromium (tests/browser.py:
the network blocked) driven by Selenium: every picture loads (and opens at full size on a click),
every table is there, nothing is fetched from outside the page, and a screenshot is not blank. The page builder's escaping and its
refusal of a missing picture are checked without a browser."""

import io
import json
from pathlib import Path

import numpy as np
import pytest
from browser import chromium, requests_made
from click.testing import CliRunner
from vibe_plates import write_plate

from pcbdyn.cli import main
from pcbdyn.report.html import Page


def run(*args):
    res = CliRunner().invoke(main, [str(a) for a in args])
    assert res.exit_code == 0, res.output
    return res


@pytest.fixture(scope="module")
def browser():
    with chromium() as driver:
        yield driver


def open_page(browser, page: Path, shot: Path) -> dict:
    """Load ``page``; return its pictures, tables and outside requests; save a screenshot."""
    browser.get(page.resolve().as_uri())
    state = browser.execute_script("""
        return {
          images: Array.from(document.querySelectorAll('figure img')).map(i => [i.complete, i.naturalWidth, i.naturalHeight]),
          tables: Array.from(document.querySelectorAll('table')).map(t => [t.dataset.title, t.rows.length]),
          fetched: performance.getEntriesByType('resource').map(e => e.name).filter(n => !n.startsWith('data:')),
          title: document.title,
          views: document.querySelectorAll('.view3d').length,
        };""")
    state["requested"] = requests_made(browser)
    png = browser.get_screenshot_as_png()
    shot.write_bytes(png)
    import matplotlib.image

    pixels = matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3]
    state["nonwhite"] = float(np.mean(pixels.min(axis=2) < 0.9))
    codes = (pixels * 15).astype(np.int64) @ np.array([256, 16, 1])
    state["colours"] = int(np.count_nonzero(np.bincount(codes.ravel())))
    return state


def check(state, n_images, titles):
    assert len(state["images"]) == n_images
    assert all(ok and w > 50 and h > 50 for ok, w, h in state["images"]), state["images"]  # none missing
    assert [t for t, _ in state["tables"]] == titles
    assert all(rows >= 2 for _, rows in state["tables"])
    assert state["fetched"] == [] and state["requested"] == []  # self-contained: nothing asked of the network
    assert state["nonwhite"] > 0.05 and state["colours"] > 20  # the screenshot is not blank


def test_vibe_page(browser, tmp_path):
    board = write_plate(tmp_path, 10.0, [("U1", 80.0, 50.0), ("U2", 40.0, 30.0)])
    run("vibe", board, "--psd", "gevs-qual", "--out", tmp_path / "out", "--html")
    state = open_page(browser, tmp_path / "out" / "report.html", tmp_path / "vibe.png")
    assert state["title"] == "pcbdyn vibe: simply supported plate"
    check(state, 2, ["Inputs", "Parts, worst margin first", "Modes", "Versions"])
    assert dict(state["tables"])["Parts, worst margin first"] == 3  # header and two parts
    assert state["views"] == 1  # the modes used, in 3-D
    # a picture opens at its full size on a click, and closes on another
    figure = browser.find_element("css selector", "figure img")
    figure.click()
    hidden, natural, shown, small_natural, small_shown = browser.execute_script("""
        const box = document.getElementById('lightbox'), img = box.querySelector('img');
        return [box.hidden, img.naturalWidth, img.getBoundingClientRect().width, arguments[0].naturalWidth,
                arguments[0].getBoundingClientRect().width];""", figure)
    assert not hidden and natural == small_natural and shown == pytest.approx(natural, abs=1)
    assert small_shown < 0.9 * natural  # the page shows it smaller
    browser.find_element("id", "lightbox").click()
    assert browser.execute_script("return document.getElementById('lightbox').hidden")


def test_build_page(browser, tmp_path):
    board = write_plate(tmp_path, 10.0, extra="")
    board.write_text(board.read_text().replace("modes = 12", "modes = 3"))
    run("build", board, "--out", tmp_path / "out", "--html")
    state = open_page(browser, tmp_path / "out" / "report.html", tmp_path / "build.png")
    check(state, 3, ["Inputs", "Model [base]", "Modes [base]", "Versions"])
    assert state["views"] == 1


def test_correlate_page(browser, tmp_path):
    board = write_plate(tmp_path, 10.0)
    board.write_text(board.read_text().replace("modes = 12", "modes = 4"))
    pts = tmp_path / "points.csv"
    pts.write_text("point,x [mm],y [mm]\n" + "".join(f"{i + 1},{x},{y}\n" for i, (x, y) in enumerate(
        (x, y) for x in (20, 50, 80, 110, 140) for y in (20, 50, 80))))
    run("simulate-test", board, "--points", pts, "--excite", "30,20", "--modes", 3, "--out", tmp_path / "t.uff")
    js = tmp_path / "c.json"
    run("correlate", board, tmp_path / "t.uff", "--out", tmp_path / "out", "--json", js, "--html")
    n_pairs = len(json.loads(js.read_text())["pairs"])
    state = open_page(browser, tmp_path / "out" / "report.html", tmp_path / "correlate.png")
    check(state, 4 + n_pairs, ["Inputs", "Mode pairs", "Lowest COMAC", "Versions"])  # MAC, AutoMAC, f, COMAC
    assert state["views"] == 1  # test and model side by side


def test_page_escapes_text_and_refuses_a_missing_picture(tmp_path):
    page = Page("a <b> & c").table("t", [{"name [mm]": "<script>alert(1)</script>", "v": 1.234567}])
    html = page.render()
    assert "<script>alert" not in html and "&lt;script&gt;alert" in html and "1.235" in html
    assert "<title>a &lt;b&gt; &amp; c</title>" in html
    with pytest.raises(FileNotFoundError, match="picture .*nothing.png for the page section 'p' does not exist"):
        Page("x").pictures("p", [tmp_path / "nothing.png"])
