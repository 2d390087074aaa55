#!/usr/bin/python3
"""The run page open in headless Chromium for a whole 30 s real-time run on
this machine, with the simulated servos in the run's own process and their
0.1 s watchdog as shipped: not one device may fault. The browser gets no
favour (it draws the 3-D view with software GL on the run's CPUs); the
simulated devices must keep their deadlines by their own priority.

Usage: dashboard_busy_run.py --animrt BIN --root SOURCE_DIR --out DIR
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dashboard_browser import PACKAGES, VIEWPORT, ERROR_HOOK, Failure, Page, Process, check, step  # noqa: E402

RUN_S = 30  # the figure: the page open for 30 s of motion


def start_browser(profile):
    """As dashboard_browser.py's, but at the browser's own priority."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for arg in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync",
                "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                f"--user-data-dir={profile}", "--window-size=1440,1100"]:
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    # A browser as a user runs it: without CAP_SYS_NICE, so that its threads
    # cannot raise their own priority (as root, Chromium puts its display
    # threads at nice -8, above the kernel workers that carry the simulated
    # servos' pty traffic).
    wrapper = os.path.join(profile + "-driver")
    with open(wrapper, "w", encoding="utf-8") as f:
        f.write("#!/bin/sh\nexec setpriv --inh-caps=-sys_nice --bounding-set=-sys_nice "
                f"{shutil.which('chromedriver')} \"$@\"\n")
    os.chmod(wrapper, 0o755)
    driver = webdriver.Chrome(service=Service(wrapper), options=options)
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           dict(VIEWPORT, deviceScaleFactor=1, mobile=False))
    driver.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": ERROR_HOOK})
    return driver


def run_test(args, pages, tmp):
    driver = start_browser(os.path.join(tmp, "profile"))
    page = Page(driver)
    pages.append(page)
    step("browser started")
    robot = os.path.join(args.root, "configs", "robots", "quadruped.yaml")
    run = Process([args.animrt, "run", robot, "--backend", "sim", "--duration", str(RUN_S),
                   "--dashboard", "127.0.0.1:0"], "animrt run", nice=0)
    try:
        url = run.wait_for(r"^dashboard: (http://\S+)", 15).group(1)
        base = url.split("?")[0].rstrip("/")

        # As in dashboard_browser.py: the page loads once the buses are
        # configured (the pings are done).
        def configured():
            check(run.proc.poll() is None, "the run ended before the page was loaded")
            try:
                phase = json.load(urllib.request.urlopen(base + "/api/state", timeout=5))["phase"]
            except OSError:
                return False
            return phase != "configure"
        page.wait("the run past configure", configured, 15)
        driver.get(url)
        page.wait("the page ready", lambda: page.js("return document.body.dataset.ready === '1';"), 15)
        page.wait("a live stream", lambda: page.js("return document.body.dataset.stream === 'live';"), 15)
        check(page.js("return document.getElementById('view3d').dataset.webgl === '1';"),
              "the 3-D view is not drawn (no WebGL): the test would not load the machine")
        gl = page.js("return document.getElementById('view3d').dataset.gl;")
        page.wait("the motion phase", lambda: page.text("#phase") == "motion", 15)
        step(f"page live ({gl} GL), run in motion")
        try:
            code = run.proc.wait(timeout=RUN_S + 30)
        except subprocess.TimeoutExpired:
            raise Failure(f"the run did not end after {RUN_S + 30} s")
        time.sleep(0.3)  # the last lines reach the reader thread
        step(f"run ended, exit {code}")
        driver.save_screenshot(os.path.join(args.out, "dashboard_busy_run.png"))
        summary = "\n".join(run.lines)
        for note in re.findall(r"(?m)^.*simulated devices: .*not permitted.*$", summary):
            print("note:", note)
        faults = re.findall(r"(?m)^.*(?:FAULT |FAULTED).*$", summary)
        print(f"device faults with the page open: {len(faults)}")
        check(not faults, "devices faulted with the page open:\n  " + "\n  ".join(faults))
        check(re.search(r"ended by duration", summary), "the run did not end by its duration")
        check(code == 0, f"the run exited {code}")
        page.assert_no_errors("during the run")
    except Failure as e:
        raise Failure(f"{e}\n--- animrt run said:\n{run.output()}") from None
    finally:
        run.stop()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--animrt", required=True)
    parser.add_argument("--root", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    try:
        import selenium  # noqa: F401
    except ImportError:
        print(f"FAIL: python3-selenium not found for {sys.executable} (apt install {PACKAGES})")
        return 1
    for tool in ("chromium", "chromedriver"):
        if not shutil.which(tool):
            print(f"FAIL: {tool} not found (apt install {PACKAGES})")
            return 1
    pages = []
    with tempfile.TemporaryDirectory() as tmp:
        try:
            run_test(args, pages, tmp)
        except Failure as e:
            print(f"FAIL: {e}")
            return 1
        finally:
            for page in pages:
                page.driver.quit()
    print("ok: 0 device faults with the run page open")
    return 0


if __name__ == "__main__":
    sys.exit(main())
