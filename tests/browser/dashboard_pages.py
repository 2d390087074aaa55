#!/usr/bin/python3
"""The dashboard's other pages in a real browser (headless Chromium, Selenium).

One browser visits, in turn:

- a show: `animrt run configs/robots/animatronic.yaml` (a show layered over
  a gait) on simulated devices, with a simulated trunk IMU pushed into a
  roll. Pause holds the playhead (it stops advancing), a seek from the seek
  bar jumps it there, play lets it advance again; the IMU panel shows the
  roll, counts and a trend of roll and pitch against the tilt limit;
- a replay: `animrt view` of a short recorded quadruped run. With the
  replay paused, the time slider moves the run's time, the joint values and
  the figure;
- a herd: `animrt herd configs/herd/gate.yaml --dashboard`. The top view
  draws every agent and they move; the page's stop ends the herd;
- an evolve run: `animrt evolve` of the quadruped with a small population.
  The fitness curves get points, the generation advances, the best gait's
  figure moves; the page's stop ends the evolution after its generation and
  the results are written.

Each fails on a script error or a console error. Screenshots go to OUT
(the build's browser/): dashboard_show.png, dashboard_view.png,
dashboard_herd.png, dashboard_evolve.png.

Usage: dashboard_pages.py --animrt BIN --root SOURCE_DIR --out DIR
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
from dashboard_browser import (PACKAGES, Failure, Page, Process, check,  # noqa: E402
                               start_browser, step)

START = time.monotonic()


def state_of(base):
    return json.load(urllib.request.urlopen(base + "/api/state", timeout=5))


def open_page(page, url):
    page.driver.get(url)
    page.wait("the page ready", lambda: page.js("return document.body.dataset.ready === '1';"), 15)
    page.wait("a live stream", lambda: page.js("return document.body.dataset.stream === 'live';"), 10)


def slide(page, selector, value):
    """Drags a range input to `value`: an input event, then the release."""
    page.js("""const s = document.querySelector(arguments[0]);
               s.value = String(arguments[1]);
               s.dispatchEvent(new Event('input'));
               s.dispatchEvent(new Event('change'));""", selector, value)


def num(page, script):
    value = page.js(script)
    return float(value) if value not in (None, "") else None


def relaxed_robot(root, name, folder, extra=""):
    """A copy of configs/robots/NAME.yaml for a busy machine: every file it
    names made absolute, generous bus timeouts and watchdogs (the browser
    shares the CPU with the simulated devices; only the page is under test
    here), short ramps."""
    source = os.path.join(root, "configs", "robots", name + ".yaml")
    here = os.path.dirname(source)
    text = open(source, encoding="utf-8").read()
    text = re.sub(r"\b(file|model|map):\s*([^\s,#}]+)",
                  lambda m: f"{m.group(1)}: {os.path.normpath(os.path.join(here, m.group(2)))}", text)
    text = re.sub(r"(?m)^(\s*watchdog_timeout_s:\s*)[\d.]+", r"\g<1>2.0", text)
    text = re.sub(r"(?m)^(\s*timeout_ms:\s*)\d+", r"\g<1>40", text)
    text = re.sub(r"(?m)^(\s*(?:start|stop)_ramp_s:\s*)[\d.]+", r"\g<1>0.5", text)
    # A Maestro's own serial timeout (100 ms by default) faults its channels
    # when the host stalls that long, as a loaded machine does.
    text = re.sub(r"(?m)^(\s*)(protocol:\s*maestro\b.*)$", r"\1\2\n\1device_watchdog_ms: 2000", text)
    path = os.path.join(folder, name + "_relaxed.yaml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text + extra)
    return path


# A simulated trunk IMU rolled to 8 degrees soon after the start, under a
# tilt watch at 40 degrees; stale only after 2 s (the machine is busy).
PUSHED_IMU = """
imus:
  - name: trunk
    protocol: bno08x_rvc
    stale_timeout_s: 2.0
    sim: {push_at_s: 0.2, push_axis: roll, push_rate_deg_s: 40, push_to_deg: 8}
"""


def check_imu_panel(page):
    check(page.js("const p = document.getElementById('panel-imus'); return !!p && !p.hidden;"),
          "no IMU panel for a robot with an IMU")
    check("40.0" in (page.text("#panel-imus .tilt-limit") or ""),
          f"the tilt limit shown: {page.text('#panel-imus .tilt-limit')}")
    roll = "return document.querySelector('#imu-table tr[data-imu=trunk] td[data-field=roll_deg]')?.dataset.value;"
    page.wait("the trunk's roll at 8 degrees", lambda: abs(float(page.js(roll) or 0) - 8.0) < 0.5, 10)
    for field in ("pitch_deg", "rates", "age", "late_cycles", "missing_reports"):
        text = page.text(f"#imu-table tr[data-imu=trunk] td[data-field={field}]")
        check(text not in (None, "", "–"), f"the IMU's {field} shows {text!r}")
    points = "return Number(document.querySelector('#imu-table tr[data-imu=trunk] canvas')?.dataset.points || 0);"
    page.wait("the attitude trend drawn", lambda: page.js(points) >= 2, 5)
    step(f"IMU panel: roll {page.js(roll)} deg, trend of {page.js(points)} points")


def show_page(args, page, tmp):
    robot = relaxed_robot(args.root, "animatronic", tmp, PUSHED_IMU)
    with open(robot, encoding="utf-8") as f:
        text = f.read()
    text = re.sub(r"(?m)^safety:\n", "safety:\n  tilt_limit_deg: 40\n", text, count=1)
    with open(robot, "w", encoding="utf-8") as f:
        f.write(text)
    run = Process([args.animrt, "run", robot,
                   "--duration", "120", "--no-realtime", "--no-audio",
                   "--dashboard", "127.0.0.1:0"], "animrt run (show)", nice=-5)
    try:
        url = run.wait_for(r"^dashboard: (http://\S+)", 20).group(1)
        base = url.split("?")[0].rstrip("/")
        open_page(page, url)
        check(page.js("return !document.getElementById('show').hidden;"), "no show controls for a show")
        page.wait("the motion phase", lambda: page.text("#phase") == "motion", 20)
        check_imu_panel(page)
        page.wait("the show controls enabled",
                  lambda: page.js("return !document.getElementById('btn-show-play').disabled;"), 5)
        position = "return document.getElementById('show-seek').value;"
        p0 = num(page, position)
        page.wait("the playhead advancing", lambda: num(page, position) > p0 + 0.2, 5)
        step("show playing")

        # Pause: the playhead stops, on the page and in the run.
        page.driver.find_element("id", "btn-show-play").click()
        page.wait("the show paused", lambda: page.text("#btn-show-play") == "Play"
                  and state_of(base)["motion"]["playing"] is False, 5)
        held = num(page, position)
        time.sleep(1.0)
        check(abs(num(page, position) - held) < 1e-6,
              f"the playhead moved while paused: {held} -> {num(page, position)}")
        check(abs(state_of(base)["motion"]["position_s"] - held) < 1e-6, "the run's show moved while paused")
        step(f"paused at {held:.2f} s, held for 1 s")

        # Seek while paused: the playhead jumps there and stays.
        duration = state_of(base)["motion"]["duration_s"]
        target = round((held + duration / 2) % duration, 2)
        slide(page, "#show-seek", target)
        page.wait(f"the playhead at {target} s", lambda: abs(
            state_of(base)["motion"]["position_s"] - target) < 1e-6, 5)
        page.wait("the seek bar at the new time", lambda: abs(num(page, position) - target) < 1e-6, 5)
        check(page.text("#show-position") == f"{target:.1f} s",
              f"the position shown is {page.text('#show-position')}, not {target:.1f} s")
        time.sleep(0.5)
        check(abs(num(page, position) - target) < 1e-6, "the playhead moved after a seek while paused")
        step(f"sought to {target} s")

        # Play: it advances again from there.
        page.driver.find_element("id", "btn-show-play").click()
        page.wait("the show playing again", lambda: page.text("#btn-show-play") == "Pause", 5)
        page.wait("the playhead advancing from the seek", lambda: (
            lambda p: p is not None and (p > target + 0.3 or p < target))(num(page, position)), 5)
        check(page.js("return document.getElementById('control-error').hidden;"),
              f"a control was refused: {page.text('#control-error')}")
        page.driver.save_screenshot(os.path.join(args.out, "dashboard_show.png"))
        page.assert_no_errors("on the show's page")
        step("playing again; dashboard_show.png")
    except Failure as e:
        raise Failure(f"{e}\n--- animrt run said:\n{run.output()}") from None
    finally:
        run.stop()


def record_walk(args, tmp):
    """A short lockstep run of the quadruped with telemetry, for the replay
    (started at once: it runs while the browser starts)."""
    csv = os.path.join(tmp, "walk.csv")
    robot = relaxed_robot(args.root, "quadruped", tmp)  # short ramps
    return csv, subprocess.Popen([args.animrt, "run", robot, "--lockstep", "--no-realtime", "--duration", "2",
                                  "--telemetry", csv], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def view_page(args, page, tmp):
    robot = os.path.join(args.root, "configs/robots/quadruped.yaml")
    csv, recording = args.recording
    try:
        _, err = recording.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        recording.kill()
        raise Failure("the recording run did not end in 60 s")
    check(recording.returncode == 0, f"the recording run exited {recording.returncode}: {err}")
    step("recording done")
    view = Process([args.animrt, "view", csv, "--robot", robot], "animrt view", nice=0)
    try:
        url = view.wait_for(r"^dashboard: (http://\S+)", 15).group(1)
        base = url.split("?")[0].rstrip("/")
        open_page(page, url)
        check(page.js("return !document.getElementById('replay').hidden;"), "no replay controls")
        info = json.load(urllib.request.urlopen(base + "/api/info", timeout=5))
        lo, hi = info["replay_range_s"]
        page.driver.find_element("id", "btn-play").click()  # pause
        pose = "return document.getElementById('view3d').dataset.pose || '';"
        meas = "return document.querySelector('#joint-list tr[data-joint=lf_knee] td[data-field=meas]').textContent;"
        marks = []
        for k, t in enumerate((lo + 0.3 * (hi - lo), lo + 0.7 * (hi - lo))):
            slide(page, "#seek", t)
            page.wait(f"the replay at {t:.2f} s", lambda: abs(state_of(base)["t_s"] - t) < 0.02, 5)
            page.wait(f"the page at {t:.2f} s", lambda: abs(float(page.text("#run-time").split()[0]) - t) < 0.02, 5)
            time.sleep(0.3)  # frames at the new time reach the figure
            marks.append((page.js(pose), page.js(meas), page.text("#run-time")))
            if k == 0:
                time.sleep(0.5)
                check(page.text("#run-time") == marks[0][2], "the replay moved while paused")
        check(marks[0][2] != marks[1][2], f"the time slider did not move the time: {marks}")
        check(marks[0][1] != marks[1][1], f"the time slider did not move the joint values: {marks}")
        if page.js("return document.getElementById('view3d').dataset.webgl;") == "1":
            check(marks[0][0] and marks[0][0] != marks[1][0], f"the time slider did not move the figure: {marks}")
        page.driver.save_screenshot(os.path.join(args.out, "dashboard_view.png"))
        page.assert_no_errors("on the replay's page")
        step("replay: the slider moves time, values and figure; dashboard_view.png")
    finally:
        view.signal(2)  # SIGINT ends the viewer
        try:
            view.proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            pass
        view.stop()
    # The viewer's stream closed: the page says so without an error.
    page.wait("'run ended'", lambda: page.text("#stream-status") == "run ended", 5)
    page.assert_no_errors("after the viewer ended")


def herd_page(args, page, tmp):
    herd = Process([args.animrt, "herd", os.path.join(args.root, "configs/herd/gate.yaml"), "--quiet",
                    "--duration", "60", "--dashboard", "127.0.0.1:0"], "animrt herd", nice=0)
    try:
        url = herd.wait_for(r"^dashboard: (http://\S+)", 15).group(1)
        open_page(page, url)
        check(page.js("return !document.getElementById('panel-herd').hidden"
                      " && document.querySelector('main').hidden;"), "the herd's panel is not the page")
        agents = json.load(urllib.request.urlopen(url.split("?")[0].rstrip("/") + "/api/info",
                                                  timeout=5))["agents"]
        page.wait(f"{agents} agents drawn", lambda: page.js(
            "return document.getElementById('herd-canvas').dataset.agents;") == str(agents), 5)
        digest = "return document.getElementById('herd-canvas').dataset.digest;"
        d0 = page.js(digest)
        page.wait("the agents moving", lambda: page.js(digest) != d0, 5)
        legend = page.text("#herd-legend") or ""
        check("crowd" in legend, f"the legend names no group kind: {legend}")
        page.driver.save_screenshot(os.path.join(args.out, "dashboard_herd.png"))
        page.driver.find_element("id", "btn-herd-stop").click()
        try:
            herd.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            raise Failure("the herd did not end after the page's stop")
        herd.wait_for(r"stopped from the dashboard", 2)
        page.wait("'run ended'", lambda: page.text("#stream-status") == "run ended", 5)
        page.assert_no_errors("on the herd's page")
        step("herd: agents drawn and moving, stopped from the page; dashboard_herd.png")
    except Failure as e:
        raise Failure(f"{e}\n--- animrt herd said:\n{herd.output()}") from None
    finally:
        herd.stop()


def evolve_page(args, page, tmp):
    run_file = os.path.join(tmp, "evolve.yaml")
    root = args.root
    with open(run_file, "w", encoding="utf-8") as f:
        f.write(f"name: dashboard_test\n"
                f"grammar: {root}/configs/grammars/quadruped_sinusoidal.bnf\n"
                f"model: {root}/configs/models/quadruped.xml\n"
                f"seed_gait: {root}/configs/gaits/quadruped_seed.yaml\n"
                "search: {seed: 3, population: 12, generations: 500, elites: 2, max_depth: 6}\n"
                "walk: {settle_s: 0.1, warmup_cycles: 1, measure_cycles: 1}\n")
    out = os.path.join(tmp, "evolved.yaml")
    evolve = Process([args.animrt, "evolve", run_file, "--out", out, "--threads", "1",
                      "--dashboard", "127.0.0.1:0"], "animrt evolve", nice=0)
    try:
        url = evolve.wait_for(r"^dashboard: (http://\S+)", 15).group(1)
        open_page(page, url)
        check(page.js("return !document.getElementById('panel-evolve').hidden"
                      " && document.querySelector('main').hidden;"), "the evolve panel is not the page")
        points = "return Number(document.getElementById('chart-fitness').dataset.points || 0);"
        generation = "return document.getElementById('evolve-generation').dataset.generation;"
        page.wait("two generations on the curves", lambda: page.js(points) >= 2, 20)
        g0 = int(page.js(generation))
        page.wait("the generation advancing", lambda: int(page.js(generation) or -1) > g0, 20)
        check(page.js(points) >= g0 + 1, f"{page.js(points)} points for generation {g0}")
        check((page.text("#evolve-generation") or "").endswith("/ 500"),
              f"the generation shown: {page.text('#evolve-generation')}")
        page.wait("the best gait's fitness", lambda: page.text("#best-fitness") not in (None, "", "–"), 5)
        if page.js("return document.getElementById('evolve-view3d').dataset.webgl;") == "1":
            pose = "return document.getElementById('evolve-view3d').dataset.pose || '';"
            p0 = page.js(pose)
            page.wait("the best gait playing on the figure", lambda: page.js(pose) not in ("", p0), 15)
        time.sleep(0.3)
        page.driver.save_screenshot(os.path.join(args.out, "dashboard_evolve.png"))
        step(f"evolve: curves with {page.js(points)} points, generation {page.js(generation)}, "
             "figure moving; dashboard_evolve.png")

        page.driver.find_element("id", "btn-evolve-stop").click()
        try:
            evolve.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            raise Failure("the evolution did not end after the page's stop")
        check(evolve.proc.returncode == 0, f"animrt evolve exited {evolve.proc.returncode}")
        evolve.wait_for(r"^stopped from the dashboard after generation \d+ of 500", 2)
        evolve.wait_for(r"^wrote ", 2)
        check(os.path.exists(out), "no gait written after the stop")
        page.wait("'run ended'", lambda: page.text("#stream-status") == "run ended", 5)
        check(page.text("#phase") == "ended", f"the phase shown at the end: {page.text('#phase')}")
        page.assert_no_errors("on the evolve page")
        step("evolve: stopped from the page, results written")
    except Failure as e:
        raise Failure(f"{e}\n--- animrt evolve said:\n{evolve.output()}") from None
    finally:
        evolve.stop()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--animrt", required=True)
    parser.add_argument("--root", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--only", choices=["show", "view", "herd", "evolve"], action="append",
                        help="visit only these pages (default: all)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    failure_shot = os.path.join(args.out, "dashboard_pages_failure.png")
    if os.path.exists(failure_shot):
        os.remove(failure_shot)  # from an earlier failing run
    try:
        import selenium  # noqa: F401
    except ImportError:
        print(f"FAIL: python3-selenium not found for {sys.executable} (apt install {PACKAGES})")
        return 1
    for tool in ("chromium", "chromedriver"):
        if not shutil.which(tool):
            print(f"FAIL: {tool} not found (apt install {PACKAGES})")
            return 1

    # The herd first: it is not timed, while the replay's recording runs.
    pages = {"herd": herd_page, "view": view_page, "show": show_page, "evolve": evolve_page}
    chosen = [name for name in pages if not args.only or name in args.only]
    driver = None
    with tempfile.TemporaryDirectory() as tmp:
        if "view" in chosen:
            args.recording = record_walk(args, tmp)
        try:
            driver = start_browser(os.path.join(tmp, "profile"))
            step("browser started")
            page = Page(driver)
            for name in chosen:
                page.driver.get("about:blank")
                page.collect_errors()
                page.console.clear()
                pages[name](args, page, tmp)
        except Failure as e:
            print(f"FAIL: {e}")
            if driver:
                try:
                    driver.save_screenshot(failure_shot)
                    errors = Page(driver).collect_errors()
                    if errors:
                        print("browser errors:\n  " + "\n  ".join(errors))
                except Exception as shot_error:  # the browser may be gone
                    print(f"(no failure screenshot: {shot_error})")
            return 1
        finally:
            if driver:
                driver.quit()
    print(f"ok: {', '.join(chosen)} pages in Chromium, screenshots in {args.out} "
          f"({time.monotonic() - START:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
