"""The widgets in a real browser (nbval cannot see a frontend).

Starts JupyterLab on a free localhost port, opens notebook 04 in headless Chromium (Debian's
chromium + chromium-driver, driven by selenium), runs every cell, moves the λ slider and checks that
the figure below it changed; a screenshot is saved (MSLIB_ARTIFACTS, else the test's tmp folder).
Skips with the reason when chromium, chromedriver or selenium is missing (.ci/run installs them).
"""
from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from contextlib import contextmanager
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "notebooks" / "04_latent_diffusion.ipynb"
CHROMIUM, CHROMEDRIVER = shutil.which("chromium"), shutil.which("chromedriver")
CHROME_FLAGS = ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                "--disable-dev-shm-usage", "--window-size=1400,1000")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait_http(url: str, timeout: float) -> None:
    t0 = time.time()
    while time.time() - t0 < timeout:
        try:
            with urllib.request.urlopen(url, timeout=5) as r:
                if r.status == 200:
                    return
        except OSError:
            time.sleep(0.5)
    raise AssertionError(f"JupyterLab did not answer at {url} within {timeout:.0f} s")


# JupyterLab's own toasts (the "receive official Jupyter news?" question) can cover, or animate over, the
# widgets a test clicks; the test server's user settings silence them all.
QUIET_LAB = {"@jupyterlab/apputils-extension/notification.jupyterlab-settings":
             {"doNotDisturbMode": True, "fetchNews": "false", "checkForUpdates": False}}


def _start_lab(folder: Path, port: int, token: str) -> subprocess.Popen:
    settings = folder / ".lab-settings"
    for name, values in QUIET_LAB.items():
        (settings / name).parent.mkdir(parents=True, exist_ok=True)
        (settings / name).write_text(json.dumps(values), encoding="utf-8")
    cmd = [sys.executable, "-m", "jupyter", "lab", "--no-browser", f"--port={port}", "--ServerApp.ip=127.0.0.1",
           f"--ServerApp.token={token}", f"--ServerApp.root_dir={folder}", "--ServerApp.port_retries=0",
           "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate", "--LabApp.news_url=None",
           f"--LabApp.user_settings_dir={settings}"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        cmd.append("--allow-root")
    env = {**os.environ, "JUPYTER_CONFIG_DIR": str(folder / ".jupyter"), "JUPYTER_RUNTIME_DIR": str(folder / ".rt")}
    return subprocess.Popen(cmd, cwd=folder, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _driver(profile: Path):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for flag in CHROME_FLAGS + (f"--user-data-dir={profile}",):
        opts.add_argument(flag)
    return webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=opts)


def _menu(wait, menu: str, item: str) -> None:
    """Click a JupyterLab main-menu entry, e.g. Run > Run All Cells."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support import expected_conditions as EC
    wait.until(EC.element_to_be_clickable(
        (By.XPATH, f"//li[contains(@class,'lm-MenuBar-item')][.//div[text()='{menu}']]"))).click()
    wait.until(EC.element_to_be_clickable(
        (By.XPATH, f"//li[contains(@class,'lm-Menu-item')][.//div[text()='{item}']]"))).click()


def _run_all_cells(driver, wait) -> None:
    """Clear the saved outputs, then Run All Cells, retried until a cell starts (a click before the
    kernel is ready is lost)."""
    from selenium.common.exceptions import TimeoutException
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support import expected_conditions as EC
    from selenium.webdriver.support.ui import WebDriverWait
    wait.until(EC.presence_of_element_located((By.CSS_SELECTOR, ".jp-NotebookPanel .jp-Cell")))
    _menu(wait, "Edit", "Clear Outputs of All Cells")

    def started(d):
        return any(any(ch.isdigit() or ch == "*" for ch in p.text)
                   for p in d.find_elements(By.CSS_SELECTOR, ".jp-InputArea-prompt"))

    for _ in range(6):
        _menu(wait, "Run", "Run All Cells")
        try:
            WebDriverWait(driver, 20).until(started)
            return
        except TimeoutException:
            continue
    raise AssertionError("JupyterLab never started running the notebook's cells")


def _figure_src(driver):
    """The slider figure's image source, or None while there is none (or it is being replaced)."""
    from selenium.common.exceptions import StaleElementReferenceException
    from selenium.webdriver.common.by import By
    imgs = driver.find_elements(By.CSS_SELECTOR, ".mslib-slider-figure img")
    try:
        return imgs[0].get_attribute("src") if imgs else None
    except StaleElementReferenceException:  # redrawn between finding and reading it
        return None


def nudge_slider(driver, css: str, key: str = "ARROW_RIGHT") -> None:
    """Move the ipywidgets slider inside the element matching the CSS selector `css`: a click on its handle, then
    the key (selenium's Keys name: ARROW_RIGHT one step right, HOME to the minimum); with continuous_update=False
    the kernel hears of it once."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support import expected_conditions as EC
    from selenium.webdriver.support.ui import WebDriverWait
    handle = driver.find_element(By.CSS_SELECTOR, f"{css} .noUi-handle")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", handle)
    # a busy machine may still be laying the widget out: clicking then raises "element not interactable"
    WebDriverWait(driver, 30).until(EC.element_to_be_clickable(handle))
    handle.click()
    handle.send_keys(getattr(Keys, key))


def move_slider_in_browser(notebook: Path, workdir: Path, artifacts: Path, timeout: float = 600.0) -> dict:
    """Run `notebook` in JupyterLab in headless Chromium, move its slider once; returns what was seen."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait
    folder = workdir / "lab"
    folder.mkdir()
    shutil.copy(notebook, folder / notebook.name)
    port, token = _free_port(), "mslib-browser-test"
    lab = _start_lab(folder, port, token)
    driver = None
    try:
        _wait_http(f"http://127.0.0.1:{port}/api/status?token={token}", 90)
        driver = _driver(workdir / "profile")
        driver.get(f"http://127.0.0.1:{port}/lab/tree/{notebook.name}?token={token}")
        wait = WebDriverWait(driver, timeout)
        _run_all_cells(driver, wait)
        wait.until(lambda d: _figure_src(d))
        # every cell has run when no prompt shows [*] and the kernel is idle again
        wait.until(lambda d: not [p for p in d.find_elements(By.CSS_SELECTOR, ".jp-InputArea-prompt")
                                  if "*" in p.text])
        before = _figure_src(driver)
        readout_before = driver.find_element(By.CSS_SELECTOR, ".mslib-slider-figure .widget-readout").text
        nudge_slider(driver, ".mslib-slider-figure")
        WebDriverWait(driver, 120).until(lambda d: _figure_src(d) not in (None, before))
        after = _figure_src(driver)
        # the screenshot shows the slider and the redrawn figure (not the cell above)
        assert not driver.find_elements(By.CSS_SELECTOR, ".jp-toast"), "a JupyterLab toast despite QUIET_LAB"
        box = driver.find_element(By.CSS_SELECTOR, ".mslib-slider-figure")
        driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", box)
        time.sleep(0.5)
        artifacts.mkdir(parents=True, exist_ok=True)
        shot = artifacts / "browser_slider_after.png"
        driver.save_screenshot(str(shot))
        label = driver.find_element(By.CSS_SELECTOR, ".mslib-slider-figure .widget-readout").text
        return {"before": before, "after": after, "screenshot": shot, "readouts": (readout_before, label)}
    finally:
        if driver is not None:
            driver.quit()
        lab.terminate()
        try:
            lab.wait(20)
        except subprocess.TimeoutExpired:
            lab.kill()


@pytest.mark.skipif(not (CHROMIUM and CHROMEDRIVER), reason="Debian's chromium and chromium-driver are not "
                    "installed (apt-get install chromium chromium-driver; .ci/run does this)")
def test_lambda_slider_redraws_the_figure_in_a_real_browser(tmp_path):
    pytest.importorskip("selenium", reason="selenium is not installed (it is in requirements.txt)")
    if not NOTEBOOK.is_file() or "slider_figure" not in NOTEBOOK.read_text(encoding="utf-8"):
        pytest.skip(f"{NOTEBOOK.name} has no slider_figure widget yet")
    artifacts = Path(os.environ.get("MSLIB_ARTIFACTS", tmp_path / "artifacts"))
    seen = move_slider_in_browser(NOTEBOOK, tmp_path, artifacts)
    assert seen["before"].startswith("data:image/png") and seen["after"].startswith("data:image/png")
    assert seen["after"] != seen["before"]
    assert seen["readouts"][0] != seen["readouts"][1]  # the slider moved to the next λ
    assert seen["screenshot"].stat().st_size > 10_000


@contextmanager
def notebook_in_lab(cells, workdir: Path, name: str = "explorer.ipynb", timeout: float = 180):
    """A notebook under `workdir` — a throwaway one of `cells` (a list of code sources), or a copy of the workbook's
    notebook when `cells` is its Path — opened in JupyterLab in headless Chromium with every cell run; yields the
    driver. JupyterLab and the browser end with the block."""
    from selenium.webdriver.support.ui import WebDriverWait
    folder = workdir / "lab"
    folder.mkdir()
    if isinstance(cells, Path):
        name = cells.name
        shutil.copy(cells, folder / name)
    else:
        nb = {"cells": [{"cell_type": "code", "execution_count": None, "id": f"c{i}", "metadata": {}, "outputs": [],
                         "source": source} for i, source in enumerate(cells)],
              "metadata": {"kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"}},
              "nbformat": 4, "nbformat_minor": 5}
        (folder / name).write_text(json.dumps(nb), encoding="utf-8")
    port, token = _free_port(), "mslib-explorer-test"
    lab = _start_lab(folder, port, token)
    try:
        _wait_http(f"http://127.0.0.1:{port}/api/status?token={token}", 90)
        with _driver(workdir / "profile") as driver:
            driver.get(f"http://127.0.0.1:{port}/lab/tree/{name}?token={token}")
            _run_all_cells(driver, WebDriverWait(driver, timeout))
            yield driver
    finally:
        stop(lab)


def stop(process) -> None:
    """End a process we started: politely, then for good after 20 s."""
    import subprocess
    process.terminate()
    try:
        process.wait(20)
    except subprocess.TimeoutExpired:
        process.kill()
