"""The browser simulator in a real browser: headless Chromium (Debian's `chromium` and
`chromium-driver`) loads the page of `plantwide serve` on column A, a screenshot is saved, and a
setpoint change made through the page's own faceplate controls moves the trend.

Run by `.ci/run` (pytest); the binary is $PLANTWIDE_BIN (default target/release/plantwide, then
target/debug/plantwide); the screenshot goes to $PLANTWIDE_SCREENSHOT (default
target/serve_column_a.png).
"""

import os
import re
import subprocess
import time
from pathlib import Path

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

ROOT = Path(__file__).resolve().parents[2]


def binary():
    env = os.environ.get("PLANTWIDE_BIN")
    if env:
        return env
    for kind in ("release", "debug"):
        p = ROOT / "target" / kind / "plantwide"
        if p.exists():
            return str(p)
    pytest.fail("no plantwide binary: build it first (cargo build --release)")


@pytest.fixture
def server():
    """`plantwide serve` on a free loopback port; stops by itself after 10 min, killed at the end."""
    proc = subprocess.Popen(
        [binary(), "serve", str(ROOT / "flowsheets/column_a.json"), "--port", "0", "--speed", "60",
         "--exit-after", "600"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        line = proc.stdout.readline()
        m = re.search(r"http://(127\.0\.0\.1:\d+)/", line)
        assert m, f"no address in {line!r}"
        yield "http://" + m.group(1) + "/"
    finally:
        proc.kill()
        proc.wait()


@pytest.fixture
def browser():
    opts = webdriver.ChromeOptions()
    for a in ("--headless", "--no-sandbox", "--disable-gpu", "--window-size=1600,1000"):
        opts.add_argument(a)
    d = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
    try:
        yield d
    finally:
        d.quit()


def trend(browser, path):
    return browser.execute_script("return (window.plantwide.data[arguments[0]] || []).slice()", path)


def test_page_setpoint_change_moves_the_trend(server, browser):
    browser.get(server)
    wait = WebDriverWait(browser, 30)
    wait.until(lambda d: d.find_elements(By.ID, "sp-condenser_level"))
    # Trends arrive: the condenser holdup is on a pen by default.
    wait.until(lambda d: len(trend(d, "column.M[41]")) > 5)
    time.sleep(2)
    shot = Path(os.environ.get("PLANTWIDE_SCREENSHOT", ROOT / "target/serve_column_a.png"))
    shot.parent.mkdir(parents=True, exist_ok=True)
    assert browser.save_screenshot(str(shot)), "screenshot"
    before = trend(browser, "column.M[41]")[-1][1]
    assert abs(before - 500.0) < 1e-3, before  # 0.5 kmol, SI

    # The faceplate's own controls: type the new setpoint, press Set.
    field = browser.find_element(By.ID, "sp-condenser_level")
    field.clear()
    field.send_keys("0.52 kmol")
    browser.find_element(By.ID, "spset-condenser_level").click()
    wait.until(lambda d: "→ at t" in d.find_element(By.ID, "message").text)
    # The setpoint pen and then the holdup follow (a P-only level loop with no load change: it settles on 0.52 kmol).
    wait.until(lambda d: trend(d, "condenser_level.sp")[-1][1] > 519.0)
    wait.until(lambda d: trend(d, "column.M[41]")[-1][1] > before + 10.0)
    assert browser.find_element(By.ID, "spv-condenser_level").text.startswith("520")

    # A refused input shows the library's message and the run goes on.
    field.clear()
    field.send_keys("0.6 furlong")
    browser.find_element(By.ID, "spset-condenser_level").click()
    wait.until(lambda d: "refused (400)" in d.find_element(By.ID, "message").text)
    t0 = browser.execute_script("return window.plantwide.state.time")
    wait.until(lambda d: d.execute_script("return window.plantwide.state.time") > t0)

    # Pause from the page stops the clock.
    browser.find_element(By.ID, "pause").click()
    wait.until(lambda d: d.find_element(By.ID, "status").text == "PAUSED")
    t1 = browser.execute_script("return window.plantwide.state.time")
    time.sleep(1.5)
    assert browser.execute_script("return window.plantwide.state.time") == t1
