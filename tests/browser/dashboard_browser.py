#!/usr/bin/python3
"""The dashboard in a real browser (headless Chromium driven by Selenium).

A real run of the quadruped against its simulated servos, served by
`animrt sim` on a pty and driven with `--backend hardware`, so that freezing
the simulator (SIGSTOP) is a genuine bus fault. The test loads the page with
the run's token and fails when

- the page raises a script error or logs an error to the console,
- a joint name of /api/info is missing from the page,
- the run's time and the measured joint values do not change,
- manual mode, a jog slider or the speed slider do not reach the run,
- the frozen servos do not show as faulted, with a fault in the log,
- the end of the run is not shown as "run ended" with the last values kept.

Screenshots of the run and of the fault go to OUT (the build's browser/).

Usage: dashboard_browser.py --animrt BIN --root SOURCE_DIR --out DIR
"""

import argparse
import json
import os
import queue
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

PACKAGES = "chromium chromium-driver python3-selenium"
VIEWPORT = {"width": 1440, "height": 1000}

# Recorded before any of the page's scripts run: errors that never reach the
# console as such (uncaught exceptions, rejected promises).
ERROR_HOOK = """
window.__pageErrors = [];
window.addEventListener('error', (e) => {
  window.__pageErrors.push(String(e.message || (e.target && (e.target.src || e.target.href)) || e));
}, true);
window.addEventListener('unhandledrejection', (e) => {
  window.__pageErrors.push('unhandled rejection: ' + String(e.reason && e.reason.message || e.reason));
});
"""


class Failure(Exception):
    pass


START = time.monotonic()


def step(what):
    print(f"[{time.monotonic() - START:5.1f} s] {what}", flush=True)


def check(condition, message):
    if not condition:
        raise Failure(message)


def favoured(nice):
    """For the child: a larger share of the CPU where permitted. The run and
    the simulated servos keep real deadlines (bus timeouts, the watchdog)
    while the browser draws and other work shares the machine; the servos
    come first, as the run's own HTTP threads share the run's priority."""
    def apply():
        try:
            os.setpriority(os.PRIO_PROCESS, 0, nice)
        except OSError:
            pass
    return apply


class Process:
    """A child process whose stdout lines are collected by a thread."""

    def __init__(self, args, name, nice):
        self.name = name
        self.lines = []
        self.queue = queue.Queue()
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, bufsize=1, preexec_fn=favoured(nice))
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))
            self.queue.put(line)

    def wait_for(self, pattern, timeout):
        regex = re.compile(pattern)
        deadline = time.monotonic() + timeout
        for line in list(self.lines):
            if m := regex.search(line):
                return m
        while time.monotonic() < deadline:
            try:
                line = self.queue.get(timeout=0.05)
            except queue.Empty:
                check(self.proc.poll() is None or not self.queue.empty(),
                      f"{self.name} ended (exit {self.proc.poll()}) before printing /{pattern}/:\n"
                      + self.output())
                continue
            if m := regex.search(line):
                return m
        raise Failure(f"{self.name} printed no /{pattern}/ in {timeout} s:\n" + self.output())

    def output(self):
        return "\n".join(self.lines[-40:])

    def signal(self, sig):
        if self.proc.poll() is None:
            os.kill(self.proc.pid, sig)

    def stop(self):
        if self.proc.poll() is None:
            self.signal(signal.SIGCONT)
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def robot_on_pty(root, pty, folder):
    """The quadruped's robot file with its bus on the simulator's pty and
    every file it names made absolute (the copy lives elsewhere)."""
    source = os.path.join(root, "configs", "robots", "quadruped.yaml")
    here = os.path.dirname(source)
    text = open(source, encoding="utf-8").read()
    text, ports = re.subn(r"(?m)^(\s*port:\s*)\S+", lambda m: m.group(1) + pty, text)
    check(ports == 1, f"expected one bus port in {source}, found {ports}")
    text = re.sub(r"(?m)^(\s*(?:file|model):\s*)([^\s#]+)",
                  lambda m: m.group(1) + os.path.normpath(os.path.join(here, m.group(2))), text)
    # The simulator is another process sharing the CPU with the browser:
    # slack, so that only the frozen simulator is a fault, not a busy machine.
    text, n = re.subn(r"(?m)^(\s*watchdog_timeout_s:\s*)[\d.]+", r"\g<1>2.0", text)
    check(n == 1, f"expected one watchdog_timeout_s in {source}")
    text, n = re.subn(r"(?m)^([ \t]*)(timeout_ms:\s*)\d+", r"\g<1>\g<2>20\n\g<1>health: packed", text)
    check(n == 1, f"expected one timeout_ms in {source}")
    # Short ramps: a shorter test.
    for key, value in (("start_ramp_s", "1.0"), ("stop_ramp_s", "0.5")):
        text, n = re.subn(rf"(?m)^(\s*{key}:\s*)[\d.]+", rf"\g<1>{value}", text)
        check(n == 1, f"expected one {key} in {source}")
    path = os.path.join(folder, "quadruped_on_pty.yaml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    return path


def start_browser(profile):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for arg in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync",
                # WebGL on the CPU, so the 3-D view is drawn without a GPU.
                "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                f"--user-data-dir={profile}", "--window-size=1440,1100"]:
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    # The browser yields the CPU to the run and the simulated servos.
    service = Service(shutil.which("chromedriver"), popen_kw={"preexec_fn": lambda: os.nice(10)})
    driver = webdriver.Chrome(service=service, options=options)
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           dict(VIEWPORT, deviceScaleFactor=1, mobile=False))
    driver.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": ERROR_HOOK})
    return driver


class Page:
    def __init__(self, driver):
        self.driver = driver
        self.console = []

    def js(self, script, *args):
        return self.driver.execute_script(script, *args)

    def wait(self, what, predicate, timeout):
        deadline = time.monotonic() + timeout
        while True:
            value = predicate()
            if value:
                return value
            if time.monotonic() > deadline:
                raise Failure(f"the page did not show {what} within {timeout} s")
            time.sleep(0.05)

    def text(self, selector):
        return self.js("const e = document.querySelector(arguments[0]); return e ? e.textContent : null;",
                       selector)

    def collect_errors(self):
        """Console errors since the last call, and script errors on the page."""
        for entry in self.driver.get_log("browser"):
            if entry.get("level") == "SEVERE":
                self.console.append(entry.get("message", str(entry)))
        errors = self.js("return window.__pageErrors || [];") or []
        page_error = self.js("const b = document.getElementById('page-error');"
                             "return b && !b.hidden ? b.textContent : '';")
        found = self.console + [f"script error: {e}" for e in errors]
        if page_error:
            found.append(f"page error banner: {page_error}")
        return found

    def assert_no_errors(self, when):
        errors = self.collect_errors()
        check(not errors, f"errors in the browser {when}:\n  " + "\n  ".join(errors))


def joint_values(page):
    return page.js("""
        const out = {};
        for (const row of document.querySelectorAll('#joint-list tr[data-joint]')) {
          const meas = row.querySelector('td[data-field=meas]');
          const cmd = row.querySelector('td[data-field=cmd]');
          out[row.dataset.joint] = {
            meas: meas && meas.dataset.value !== undefined ? Number(meas.dataset.value) : null,
            cmd: cmd && cmd.dataset.value !== undefined ? Number(cmd.dataset.value) : null,
            text: row.textContent };
        }
        return out;""")


def run_test(args, tmp, page_holder):
    # The browser first: its start-up is the busiest moment of the test.
    driver = start_browser(os.path.join(tmp, "profile"))
    page = Page(driver)
    page_holder.append(page)
    step("browser started")
    sim = Process([args.animrt, "sim", os.path.join(args.root, "configs/robots/quadruped.yaml")],
                  "animrt sim", nice=-15)
    run = None
    try:
        pty = sim.wait_for(r"^serial legs (/dev/pts/\d+)", 10).group(1)
        robot = robot_on_pty(args.root, pty, tmp)
        run = Process([args.animrt, "run", robot, "--backend", "hardware", "--duration", "60",
                       "--no-realtime", "--dashboard", "127.0.0.1:0"], "animrt run", nice=-5)
        url = run.wait_for(r"^dashboard: (http://\S+)", 15).group(1)
        check("token=" in url, f"the dashboard line has no token: {url}")
        base = url.split("?")[0].rstrip("/")
        info = json.load(urllib.request.urlopen(base + "/api/info", timeout=5))
        names = [j["name"] for j in info["joints"]]
        check(len(names) == 12, f"/api/info lists {len(names)} joints: {names}")

        # The pages load once the buses are configured (the pings are done).
        def configured():
            check(run.proc.poll() is None, "the run ended before the page was loaded")
            try:
                phase = json.load(urllib.request.urlopen(base + "/api/state", timeout=5))["phase"]
            except OSError:
                return False  # the run is ending; the next call says so
            return phase != "configure"
        Page(driver).wait("the run past configure", configured, 15)
        step("run configured")


        # Without the token: every control disabled, a read-only note.
        driver.get(base + "/")
        page.wait("the page ready", lambda: page.js("return document.body.dataset.ready === '1';"), 10)
        check(page.js("return !document.getElementById('readonly-note').hidden;"),
              "no read-only note without a token")
        check(page.js("return document.getElementById('btn-stop').disabled;"),
              "the stop button is enabled without a token")
        page.assert_no_errors("on the read-only page")
        step("read-only page checked")

        # With the token, live.
        driver.get(url)
        page.wait("the page ready", lambda: page.js("return document.body.dataset.ready === '1';"), 10)
        page.wait("a live stream", lambda: page.js("return document.body.dataset.stream === 'live';"), 10)
        check(page.js("return document.getElementById('readonly-note').hidden;"),
              "the read-only note shows although the page has the token")

        # The stream opens before its first state: the device table fills from that.
        page.wait("a first state in the device table", lambda: page.js(
            "return document.querySelectorAll('#device-table tbody tr').length > 0;"), 10)
        rows = joint_values(page)
        devices = page.text("#device-table") or ""
        for name in names:
            check(name in rows and name in rows[name]["text"], f"joint {name} missing from the joint list")
            check(name in devices, f"joint {name} missing from the device table")
        check(page.text("#robot-name") == info["robot"], f"robot name shown: {page.text('#robot-name')}")

        page.wait("the motion phase", lambda: page.text("#phase") == "motion", 15)
        step("joint names shown; in motion")
        # Health read (health: packed): each device's trend plot draws its
        # temperature and current over the last seconds.
        page.wait("trend plots with points", lambda: page.js(
            "const c = [...document.querySelectorAll('#device-table canvas.spark')];"
            "return c.length === 12 && c.every((x) => Number(x.dataset.points) >= 3"
            " && x.title.includes('temperature') && x.title.includes('current'));"), 10)
        check(page.js(
            "const c = document.querySelector('#device-table canvas.spark');"
            "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
            "return d.some((v, i) => i % 4 === 3 && v > 0);"), "a trend plot is blank")
        step("trend plots drawn")
        t0, v0 = page.text("#run-time"), joint_values(page)
        time.sleep(1.0)
        t1, v1 = page.text("#run-time"), joint_values(page)
        check(t0 != t1, f"the run time did not change over a second: {t0}")
        moved = [n for n in names if v0[n]["meas"] is not None and v1[n]["meas"] is not None
                 and v0[n]["meas"] != v1[n]["meas"]]
        check(moved, f"no measured joint value changed over a second: {v1}")

        # The figure: drawn when the robot has a model, a note otherwise.
        view = page.js("const v = document.getElementById('view3d');"
                       "return {webgl: v.dataset.webgl, model: v.dataset.model,"
                       " note: document.getElementById('view3d-note').hidden ? '' :"
                       " document.getElementById('view3d-note').textContent};")
        if view["webgl"] != "1":
            check(view["note"], "no WebGL and no note saying so")
            print(f"note: no WebGL in this browser: {view['note']}")
        elif info.get("model"):
            check(view["model"] == str(len(info["model"]["bodies"])),
                  f"the 3-D view has {view['model']} bodies, the model {len(info['model']['bodies'])}")
        else:
            check(view["note"], "no model and no note saying so")
        time.sleep(0.3)  # a few frames more for the charts
        driver.save_screenshot(os.path.join(args.out, "dashboard_run.png"))
        step("live values change; dashboard_run.png")

        # Manual mode, one jog, back to the motion.
        driver.find_element("id", "manual-toggle").click()
        page.wait("manual mode on", lambda: page.js(
            "return document.getElementById('manual-toggle').checked &&"
            " !document.getElementById('jog-sliders').hidden;"), 5)
        step("manual mode on")
        held = joint_values(page)["lf_knee"]["cmd"] or 0.0
        target = round(held + (0.15 if held < 0 else -0.15), 3)
        page.js("""const s = document.querySelector('#jog-sliders input[data-joint="lf_knee"]');
                   s.value = String(arguments[0]);
                   s.dispatchEvent(new Event('input'));
                   s.dispatchEvent(new Event('change'));""", target)
        page.wait(f"lf_knee commanded to {target} rad", lambda: abs(
            (joint_values(page)["lf_knee"]["cmd"] or 1e9) - target) < 0.02, 10)
        step("jogged")
        check(page.js("return document.getElementById('control-error').hidden;"),
              f"a control was refused: {page.text('#control-error')}")
        driver.find_element("id", "btn-resume").click()
        page.wait("manual mode off", lambda: page.js(
            "return !document.getElementById('manual-toggle').checked;"), 5)
        step("manual mode, jog, back to the motion")

        # Steering: the speed slider's value reaches the gait.
        if info["motion"].get("steerable"):
            lo, hi = info["motion"]["speed_mps"]
            speed = round(lo + 0.6 * (hi - lo), 4)
            page.js("""const s = document.getElementById('steer-speed');
                       s.value = String(arguments[0]);
                       s.dispatchEvent(new Event('input'));
                       s.dispatchEvent(new Event('change'));""", speed)

            def steered():
                state = json.load(urllib.request.urlopen(base + "/api/state", timeout=5))
                got = state["motion"].get("speed_mps")
                return got is not None and abs(got - speed) < 1e-3
            page.wait(f"the gait steered to {speed} m/s", steered, 5)
            check(page.js("return document.getElementById('control-error').hidden;"),
                  f"steering was refused: {page.text('#control-error')}")

        # A fault: the simulated servos stop answering.
        sim.signal(signal.SIGSTOP)
        page.wait("a faulted device", lambda: page.js(
            "return document.querySelectorAll('#device-table tr[data-health=faulted]').length > 0;"), 5)
        page.wait("a fault in the log", lambda: page.js(
            "return document.querySelectorAll('#fault-log li.fault').length > 0;"), 5)
        time.sleep(0.5)
        driver.save_screenshot(os.path.join(args.out, "dashboard_fault.png"))
        step("fault shown, dashboard_fault.png: " + (page.text("#fault-log li.fault") or ""))

        # The end of the run: the stream closes, the last values stay.
        sim.signal(signal.SIGCONT)
        try:
            run.proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            raise Failure("the run did not end after the fault:\n" + run.output())
        page.wait("'run ended'", lambda: page.text("#stream-status") == "run ended", 5)
        last = joint_values(page)
        check(all(last[n]["meas"] is not None for n in names), "joint values lost at the end of the run")
        page.assert_no_errors("during the run")
        step("run ended, last values kept, no browser errors")
    except Failure as e:
        if run:
            raise Failure(f"{e}\n--- animrt run said:\n{run.output()}") from None
        raise
    finally:
        if run:
            run.stop()
        sim.stop()


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
            run_test(args, tmp, pages)
        except Failure as e:
            print(f"FAIL: {e}")
            if pages:
                try:
                    pages[0].driver.save_screenshot(os.path.join(args.out, "dashboard_failure.png"))
                    errors = pages[0].collect_errors()
                    if errors:
                        print("browser errors:\n  " + "\n  ".join(errors))
                except Exception as shot_error:  # the browser may be gone
                    print(f"(no failure screenshot: {shot_error})")
            return 1
        finally:
            for page in pages:
                page.driver.quit()
    print(f"ok: dashboard in Chromium, screenshots in {args.out} ({time.monotonic() - START:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
