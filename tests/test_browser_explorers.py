"""An explorer operated in a real browser: JupyterLab in headless Chromium, as tests/test_browser_widgets.py.

A throwaway notebook (under the test's tmp folder) shows `explore_transfer` with the identity method; the test
picks another method in the method dropdown and checks that the kernel answered (the status line names it) and
that the viewer's canvas pixels changed. Screenshots before and after go to MSLIB_ARTIFACTS (else the tmp
folder). ~25 s (JupyterLab start, kernel start, the checkpoints' loading). Skips when chromium, chromedriver or
selenium is missing.
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from tests.test_browser_viewer import pixels
from tests.test_browser_widgets import CHROMEDRIVER, CHROMIUM, notebook_in_lab

pytestmark = pytest.mark.skipif(not (CHROMIUM and CHROMEDRIVER), reason="Debian's chromium and chromium-driver "
                                "are not installed (apt-get install chromium chromium-driver; .ci/run does this)")

CELL = """\
from mslib.explorers import explore_transfer
explore_transfer("c00000", "old", "identity")"""
BOX = ".jp-OutputArea .mslib-explorer-transfer"


def _status(driver) -> str:
    from selenium.webdriver.common.by import By
    found = driver.find_elements(By.CSS_SELECTOR, f"{BOX} .mslib-explorer-status")
    return found[0].text if found else ""


def _screenshot(driver, path: Path) -> Path:
    from selenium.webdriver.common.by import By
    for button in driver.find_elements(By.XPATH, "//div[contains(@class,'jp-toast')]//button[text()='No']"):
        button.click()   # the news toast
    box = driver.find_element(By.CSS_SELECTOR, BOX)
    driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", box)
    time.sleep(0.5)
    driver.save_screenshot(str(path))
    return path


def likely_styles(driver) -> list:
    """The classes whose bar shows P > 0.5 (read from the bars' data attributes)."""
    from selenium.webdriver.common.by import By
    bars = driver.find_elements(By.CSS_SELECTOR, f"{BOX} .mslib-explorer-bars .mslib-bar")
    assert len(bars) == 8
    return [b.get_attribute("data-class") for b in bars if float(b.get_attribute("data-p")) > 0.5]


def test_transfer_explorer_changes_method_in_jupyterlab(tmp_path):
    pytest.importorskip("selenium", reason="selenium is not installed (it is in requirements.txt)")
    pytest.importorskip("anywidget", reason="anywidget is in the notebooks extra")
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select, WebDriverWait
    artifacts = Path(os.environ.get("MSLIB_ARTIFACTS") or tmp_path / "artifacts")
    artifacts.mkdir(parents=True, exist_ok=True)
    with notebook_in_lab([CELL], tmp_path) as driver:
        WebDriverWait(driver, 180).until(lambda d: d.find_elements(By.CSS_SELECTOR, f"{BOX} .mslib-viewer-canvas"))
        WebDriverWait(driver, 30).until(lambda d: "identity" in _status(d))
        before, styles_before = pixels(driver), likely_styles(driver)
        assert before["drawn"] > 0.02 * before["total"], before
        assert min(before["counts"]["left"], before["counts"]["right"]) > 200, before["counts"]
        _screenshot(driver, artifacts / "explorer_transfer_before.png")

        select = driver.find_element(By.CSS_SELECTOR, f"{BOX} .mslib-explorer-method select")
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", select)
        Select(select).select_by_visible_text("adain")
        WebDriverWait(driver, 60).until(lambda d: "adain" in _status(d))    # the kernel answered
        WebDriverWait(driver, 10).until(lambda d: pixels(d)["digest"] != before["digest"])
        after = pixels(driver)
        assert min(after["counts"]["left"], after["counts"]["right"]) > 200, after["counts"]
        assert likely_styles(driver) == ["old"] != styles_before             # the bars followed
        shot = _screenshot(driver, artifacts / "explorer_transfer_after.png")
        assert shot.stat().st_size > 10_000
        errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        assert not [e for e in errors if "mslib" in e["message"] or "viewer" in e["message"]], errors


def test_notebook_02s_transfer_explorer_answers_in_jupyterlab(tmp_path):
    """The workbook's own notebook 02, run top to bottom in JupyterLab: its explorer (adain → old) is switched to
    the identity method, and the view and the bars follow (~60 s: the notebook's live training runs too)."""
    pytest.importorskip("selenium", reason="selenium is not installed (it is in requirements.txt)")
    pytest.importorskip("anywidget", reason="anywidget is in the notebooks extra")
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select, WebDriverWait
    notebook = Path(__file__).resolve().parents[1] / "notebooks" / "02_adain_transfer.ipynb"
    artifacts = Path(os.environ.get("MSLIB_ARTIFACTS") or tmp_path / "artifacts")
    artifacts.mkdir(parents=True, exist_ok=True)
    with notebook_in_lab(notebook, tmp_path, timeout=600) as driver:
        WebDriverWait(driver, 600).until(lambda d: "adain" in _status(d))
        WebDriverWait(driver, 60).until(lambda d: d.find_elements(By.CSS_SELECTOR, f"{BOX} .mslib-viewer-canvas"))
        assert likely_styles(driver) == ["old"]
        before = pixels(driver, f"{BOX} .mslib-viewer-canvas")
        select = driver.find_element(By.CSS_SELECTOR, f"{BOX} .mslib-explorer-method select")
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", select)
        Select(select).select_by_visible_text("identity")
        WebDriverWait(driver, 60).until(lambda d: "identity" in _status(d))
        canvas = f"{BOX} .mslib-viewer-canvas"
        WebDriverWait(driver, 10).until(lambda d: pixels(d, canvas)["digest"] != before["digest"])
        assert likely_styles(driver) != ["old"]  # the content walk is not read as old
        shot = _screenshot(driver, artifacts / "notebook02_explorer_identity.png")
        assert shot.stat().st_size > 10_000
