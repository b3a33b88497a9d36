"""The 3-D viewer's standalone page (viz.viewer_html) in a real browser: headless Chromium, file://, no server.

Checks that the canvas draws (the floor, both side colours, a lit foot), that a mouse drag orbits and the wheel
zooms (the pixels change, the frame does not), that play advances the frames and pause stops them, and that the
scrub bar and the arrow keys set the frame. Screenshots go to MSLIB_ARTIFACTS (else the test's tmp folder).
Skips like tests/test_browser_widgets.py when chromium, chromedriver or selenium is missing.
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from mslib import viz
from tests.test_browser_widgets import CHROMEDRIVER, CHROMIUM, _driver
from tests.test_viewer import made_up_walk

pytestmark = pytest.mark.skipif(not (CHROMIUM and CHROMEDRIVER), reason="Debian's chromium and chromium-driver "
                                "are not installed (apt-get install chromium chromium-driver; .ci/run does this)")

# JavaScript run in the page: how many canvas pixels are near each colour, and a digest of all of them
COUNT_COLOURS = """
const canvas = document.querySelector(arguments[1]);
const d = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
const near = (i, c) => Math.abs(d[i] - c[0]) + Math.abs(d[i + 1] - c[1]) + Math.abs(d[i + 2] - c[2]) < 40;
const colours = arguments[0], counts = Object.fromEntries(Object.keys(colours).map((k) => [k, 0]));
let digest = 0, drawn = 0;
for (let i = 0; i < d.length; i += 4) {
  if (!near(i, [251, 251, 251])) drawn++;
  for (const k in colours) if (near(i, colours[k])) counts[k]++;
  digest = (digest * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) % 1000000007;
}
return {counts, drawn, digest, total: d.length / 4};
"""


def rgb(hex_colour: str) -> list:
    return [int(hex_colour[k:k + 2], 16) for k in (1, 3, 5)]


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    pytest.importorskip("selenium", reason="selenium is not installed (it is in requirements.txt)")
    folder = tmp_path_factory.mktemp("viewer")
    walk = made_up_walk(60)
    html = viz.viewer_html([walk, walk[:40]], titles=["content walk", "output"], page_title="viewer test",
                           follow=True)
    path = folder / "viewer.html"
    path.write_text(html, encoding="utf-8")
    driver = _driver(folder / "profile")
    try:
        driver.get(path.as_uri())
        yield driver
    finally:
        driver.quit()


def frame(driver) -> int:
    return int(driver.execute_script("return document.querySelector('.mslib-viewer').dataset.frame"))


def pixels(driver, canvas: str = ".mslib-viewer-canvas") -> dict:
    """Counts of the viewer's colours in the first canvas matching the CSS selector `canvas`, and a digest."""
    colours = {"left": rgb(viz.SIDE_COLOURS["left"]), "right": rgb(viz.SIDE_COLOURS["right"]),
               "contact": rgb(viz.viewer.CONTACT_COLOUR), "grid": [221, 221, 221]}
    return driver.execute_script(COUNT_COLOURS, colours, canvas)


def test_viewer_draws_orbits_zooms_and_plays_in_chromium(page, tmp_path):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.actions.wheel_input import ScrollOrigin
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait
    driver = page
    artifacts = Path(os.environ.get("MSLIB_ARTIFACTS") or tmp_path)
    artifacts.mkdir(parents=True, exist_ok=True)
    WebDriverWait(driver, 20).until(lambda d: d.execute_script(
        "const v = document.querySelector('.mslib-viewer'); return v && v.dataset.frame !== undefined"))
    errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
    assert not errors, errors
    canvas = driver.find_element(By.CSS_SELECTOR, ".mslib-viewer-canvas")
    titles = driver.execute_script("return document.title")
    assert titles == "viewer test" and frame(driver) == 0

    # 1. not blank: the floor grid, both sides of the body, a foot lit (the right foot stands at frame 0)
    first = pixels(driver)
    assert first["drawn"] > 0.02 * first["total"], first
    assert min(first["counts"]["left"], first["counts"]["right"]) > 200, first["counts"]
    assert first["counts"]["contact"] > 50 and first["counts"]["grid"] > 200, first["counts"]
    driver.save_screenshot(str(artifacts / "viewer_start.png"))

    # 2. a drag orbits: other pixels, same frame
    ActionChains(driver).move_to_element(canvas).click_and_hold().move_by_offset(90, 25).release().perform()
    orbited = pixels(driver)
    assert orbited["digest"] != first["digest"] and frame(driver) == 0
    assert min(orbited["counts"]["left"], orbited["counts"]["right"]) > 200
    driver.save_screenshot(str(artifacts / "viewer_orbited.png"))

    # 3. the wheel zooms
    ActionChains(driver).scroll_from_origin(ScrollOrigin.from_element(canvas), 0, -300).perform()
    WebDriverWait(driver, 5).until(lambda d: pixels(d)["digest"] != orbited["digest"])
    assert frame(driver) == 0

    # 4. play advances the frames (20 fps: a second is ~20 frames), pause stops them
    driver.find_element(By.CSS_SELECTOR, ".mslib-viewer-play").click()
    t0 = time.time()
    WebDriverWait(driver, 10).until(lambda d: frame(d) >= 10)
    assert time.time() - t0 < 8
    driver.save_screenshot(str(artifacts / "viewer_playing.png"))
    driver.find_element(By.CSS_SELECTOR, ".mslib-viewer-play").click()
    stopped = frame(driver)
    time.sleep(0.4)
    assert frame(driver) == stopped and "play" in driver.find_element(By.CSS_SELECTOR, ".mslib-viewer-play").text

    # 5. the scrub bar and the arrow keys set the frame; the time label follows
    driver.execute_script("const s = document.querySelector('.mslib-viewer-scrub'); s.value = 42;"
                          "s.dispatchEvent(new Event('input'));")
    WebDriverWait(driver, 2).until(lambda d: frame(d) == 42)
    canvas.send_keys(Keys.ARROW_RIGHT)
    WebDriverWait(driver, 2).until(lambda d: frame(d) == 43)
    label = driver.find_element(By.CSS_SELECTOR, ".mslib-viewer-time").text
    assert label.startswith("2.15 s") and label.endswith("2.95 s"), label
    # the short motion holds its last pose once it has ended: still both sides drawn
    assert min(pixels(driver)["counts"][k] for k in ("left", "right")) > 200
    for name in ("viewer_start.png", "viewer_orbited.png", "viewer_playing.png"):
        assert (artifacts / name).stat().st_size > 10_000, name


# ---------------------------------------------------------------- the live widget in JupyterLab
WIDGET_CELL = """\
import numpy as np
from mslib import viz
from mslib.motion.skeleton import HUMANML3D
rest = HUMANML3D.rest_positions()
rest[:, 1] -= rest[:, 1].min()
walk = np.repeat(rest[None], 60, axis=0)
walk[:, :, 2] += np.arange(60)[:, None] / 20
viewer = viz.MotionViewer([walk, walk[::-1]], titles=["forward", "backward"])
viewer"""


def test_motion_viewer_widget_plays_in_jupyterlab(tmp_path):
    """A throwaway notebook (under tmp) showing a MotionViewer: the widget, not its stand-in picture, is drawn
    and plays; ~30 s (JupyterLab start, kernel start)."""
    pytest.importorskip("selenium", reason="selenium is not installed (it is in requirements.txt)")
    pytest.importorskip("anywidget", reason="anywidget is in the notebooks extra")
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    from tests.test_browser_widgets import notebook_in_lab
    with notebook_in_lab([WIDGET_CELL], tmp_path, "viewer.ipynb") as driver:
        WebDriverWait(driver, 180).until(
            lambda d: d.find_elements(By.CSS_SELECTOR, ".jp-OutputArea .mslib-viewer-canvas"))
        # JupyterLab prefers the widget: the stand-in picture is not shown beside it
        assert not driver.find_elements(By.CSS_SELECTOR, ".jp-OutputArea img")
        drawn = pixels(driver)
        assert drawn["drawn"] > 0.02 * drawn["total"]
        assert min(drawn["counts"]["left"], drawn["counts"]["right"]) > 200, drawn["counts"]
        driver.find_element(By.CSS_SELECTOR, ".mslib-viewer-play").click()
        WebDriverWait(driver, 10).until(lambda d: frame(d) >= 10)
        shot = Path(os.environ.get("MSLIB_ARTIFACTS") or tmp_path) / "viewer_jupyterlab.png"
        shot.parent.mkdir(parents=True, exist_ok=True)
        driver.save_screenshot(str(shot))
        assert shot.stat().st_size > 10_000
