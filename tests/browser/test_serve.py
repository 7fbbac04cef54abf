"""The browser simulator in a real browser: headless Chromium (Debian's `chromium` and
`chromium-driver`) loads the page of `plantwide serve` on column A, a screenshot is saved, a
setpoint change made through the page's own faceplate controls moves the trend (the page's commands
carry the session token it was served), a feed step made through the page settles on the steady
state and equals the scenario-file run, and a page of another origin cannot command the server.

Run by `.ci/run` (pytest); the binary is $PLANTWIDE_BIN (default target/release/plantwide, then
target/debug/plantwide); the screenshot goes to $PLANTWIDE_SCREENSHOT (default
target/serve_column_a.png).
"""

import http.server
import json
import os
import re
import subprocess
import threading
import time
import urllib.request
from pathlib import Path

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

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
    # The faceplate polls the state twice a second.
    wait.until(lambda d: d.find_element(By.ID, "spv-condenser_level").text.startswith("520"))

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


def api(base, path):
    with urllib.request.urlopen(base + path) as r:
        return json.load(r)


def test_page_feed_step_reaches_the_steady_state_and_equals_the_scenario_run(server, browser, tmp_path):
    """Column A: the feed stepped 1 → 1.01 kmol/min from the page's input panel, the clock at ×10⁴
    from the page's speed control; after 3000 min xB is the steady state `steady --set` gives, and
    the journal's scenario run by `plantwide run` ends where the live run is, to 1e-10."""
    browser.get(server + "?pens=bottoms.x[light],distillate.x[light],column.M[1]")
    wait = WebDriverWait(browser, 30)
    wait.until(lambda d: d.find_elements(By.ID, "input-path"))
    Select(browser.find_element(By.ID, "input-path")).select_by_visible_text("feed_source.F")
    browser.find_element(By.ID, "input-value").send_keys("1.01 kmol/min")
    browser.find_element(By.ID, "input-set").click()
    wait.until(lambda d: "→ at t" in d.find_element(By.ID, "message").text)
    Select(browser.find_element(By.ID, "speed")).select_by_value("10000")
    WebDriverWait(browser, 240).until(lambda d: d.execute_script("return window.plantwide.state.time") > 3000 * 60)
    time.sleep(1)
    shot = Path(os.environ.get("PLANTWIDE_SCREENSHOT_STEP", ROOT / "target/serve_column_a_feed_step.png"))
    browser.save_screenshot(str(shot))
    browser.find_element(By.ID, "pause").click()
    wait.until(lambda d: d.find_element(By.ID, "status").text == "PAUSED")

    live = api(server, "api/state?at=sync")
    xb = live["values"]["bottoms.x[light]"]
    out = subprocess.run([binary(), "steady", str(ROOT / "flowsheets/column_a.json"), "--json",
                          "--set", "feed_source.F=1.01kmol/min"], capture_output=True, text=True, check=True)
    steady = json.loads(out.stdout)["values"]["bottoms.x[light]"]
    print(f"xB live {xb!r} at {live['time'] / 60:.1f} min, steady --set {steady!r}")
    assert abs(xb - steady) <= 1e-6 * steady

    journal = api(server, "api/journal")
    assert [e["path"] for e in journal["events"]] == ["feed_source.F"]
    journal["record"] = {"interval": journal["duration"], "paths": ["bottoms.x[light]", "distillate.x[light]"]}
    scen = tmp_path / "journal.json"
    scen.write_text(json.dumps(journal))
    out = subprocess.run([binary(), "run", str(ROOT / "flowsheets/column_a.json"), "--scenario", str(scen),
                          "--csv", str(tmp_path / "journal.csv"), "--json"], capture_output=True, text=True, check=True)
    ran = json.loads(out.stdout)
    assert ran["t_end"] == live["time"]
    for p in ("bottoms.x[light]", "distillate.x[light]"):
        diff = abs(ran["final_values"][p] - live["values"][p])
        print(f"{p}: live vs scenario file |Δ| = {diff:.3e}")
        assert diff <= 1e-10


@pytest.fixture
def foreign_site():
    """Another origin on loopback: an empty page served on a free port of 127.0.0.1."""
    class Page(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            body = b"<!doctype html><title>another site</title><form id=f method=post></form>"
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass

    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Page)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}/"
    finally:
        httpd.shutdown()


def test_a_page_of_another_origin_cannot_command_the_server(server, browser, foreign_site):
    """What any web page can send without a CORS preflight: a text/plain fetch and a form post,
    from its own origin to the server on 127.0.0.1. Both are refused; the clock keeps running."""
    assert api(server, "api/state")["running"]
    browser.get(foreign_site)
    statuses = browser.execute_async_script("""
        const [url, done] = [arguments[0], arguments[arguments.length - 1]];
        const body = JSON.stringify({pause: true});
        // no-cors: the request is sent, its answer hidden from the page.
        fetch(url + 'api/command', {method: 'POST', mode: 'no-cors', headers: {'Content-Type': 'text/plain'}, body})
          .then(r => r.type, e => 'error: ' + e).then(done);
    """, server)
    assert statuses == "opaque", statuses
    assert api(server, "api/state")["running"], "a foreign page's fetch paused the clock"
    # A form post, the other request a page sends unasked; as text/plain its body reads as JSON
    # ({"pause": true, "x": "="}).
    browser.execute_script("""
        const f = document.getElementById('f');
        f.action = arguments[0] + 'api/command';
        f.enctype = 'text/plain';
        const i = document.createElement('input');
        i.name = '{"pause": true, "x": "'; i.value = '"}';
        f.appendChild(i);
        f.submit();
    """, server)
    WebDriverWait(browser, 30).until(lambda d: d.current_url.startswith(server))
    answer = browser.find_element(By.TAG_NAME, "body").text
    assert "are refused" in answer, answer
    assert api(server, "api/state")["running"], "a foreign page's form paused the clock"
