#!/usr/bin/env python3
"""Opens each live lesson page in headless Chromium with page_test.js put into a copy of it, and
checks what the test found: no console error, time advances in every scene, a scene with a
ground is framed down to it, a slider changes the motion (and each is labelled apart from the
others under its table), a drag moves the grabbed particle, an edited scene's error shows
FILE:LINE:COL, the strain at each particle comes from the engine, a slider keeps a cloth's
tears, the engine names its planes, and side by side the same build never differs while a
particle moved in one alone is the first difference (and, on a student page built on the stubs,
the exercise's message, and the frame where the stub stops as the first difference from the
reference). And a browser without WebAssembly SIMD, which the module needs, is told so in the
page; and an address that names a scene, a time and `paused` opens the page there."""

import argparse
import base64
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import threading

CAPTURE = """<script>
window.__clothlabErrors = [];
window.addEventListener('error', (e) => window.__clothlabErrors.push(String(e.message)));
window.addEventListener('unhandledrejection', (e) => window.__clothlabErrors.push(String(e.reason)));
const __clothlabConsoleError = console.error;
console.error = (...args) => { window.__clothlabErrors.push(args.join(' ')); __clothlabConsoleError(...args); };
</script>"""


def browser() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return name
    if os.environ.get("CLOTHLAB_REQUIRE_WEB") == "1" or os.environ.get("CLOTHLAB_REQUIRE_BROWSER") == "1":
        sys.exit("check_pages: no Chromium found (apt-get install -y chromium)")
    print("check_pages: no Chromium found (apt-get install -y chromium): skipped")
    sys.exit(77)


def run_until_reported(command: list, tag: str, timeout: float):
    """Runs the browser until a console line starting with `tag` arrives (its base64 JSON is
    returned), or `timeout` seconds pass (None). Real time: the page's clock is not virtual."""
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               text=True)
    timer = threading.Timer(timeout, process.kill)
    timer.start()
    try:
        for line in process.stderr:
            at = line.find(tag)
            if at >= 0:
                encoded = re.match(r"[A-Za-z0-9+/=]+", line[at + len(tag):]).group(0)
                return json.loads(base64.b64decode(encoded).decode("utf-8"))
        return None
    finally:
        timer.cancel()
        process.kill()
        process.wait()


def drive(url: str, tag: str, timeout: float):
    """Opens `url` in headless Chromium with WebGL (SwiftShader) and returns what the page
    reports on the console line starting with `tag` (None if nothing within `timeout` s)."""
    command = [browser(), "--headless", "--no-sandbox", "--disable-dev-shm-usage",
               "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
               "--window-size=1200,800", "--enable-logging=stderr", "--v=0", url]
    return run_until_reported(command, tag, timeout)


def check(page: pathlib.Path, test_script: str, work: pathlib.Path) -> list:
    text = page.read_text(encoding="utf-8")
    text = text.replace("<head>", "<head>\n" + CAPTURE, 1)
    text = text.replace("</body>", "<script>" + test_script + "</script>\n</body>", 1)
    copy = work / page.name
    copy.write_text(text, encoding="utf-8")
    results = drive(copy.resolve().as_uri(), "CLOTHLAB-TEST ", timeout=240)
    if results is None:
        return [f"{page.name}: the page reported nothing within 240 s"]
    problems = [f"{page.name}: console error: {e}" for e in results["errors"]]
    for c in results["checks"]:
        status = "ok  " if c["ok"] else "FAIL"
        print(f"  {status} {page.name}: {c['name']}")
        if not c["ok"]:
            problems.append(f"{page.name}: {c['name']}: {c['detail']}")
    if not results["checks"]:
        problems.append(f"{page.name}: no check ran")
    return problems


def check_without_simd(page: pathlib.Path, work: pathlib.Path) -> list:
    """The page in a browser that cannot compile SIMD (every WebAssembly module found invalid,
    as such a browser finds the engine's) says what it lacks instead of failing silently."""
    text = page.read_text(encoding="utf-8").replace(
        "<head>", "<head>\n<script>WebAssembly.validate = () => false;</script>", 1)
    copy = work / ("no-simd-" + page.name)
    copy.write_text(text, encoding="utf-8")
    command = [browser(), "--headless", "--no-sandbox", "--disable-dev-shm-usage",
               "--disable-3d-apis", "--dump-dom", copy.resolve().as_uri()]
    dom = subprocess.run(command, capture_output=True, text=True, timeout=120).stdout
    found = re.search(r'<div id="message"[^>]*>([^<]*)<', dom)
    message = found.group(1) if found else "(no message box)"
    ok = "WebAssembly with SIMD" in message
    print(f"  {'ok  ' if ok else 'FAIL'} {page.name}: without WebAssembly SIMD, the page says so")
    return [] if ok else [f"{page.name}: without WebAssembly SIMD the page said: {message}"]


def last_scene(page: pathlib.Path) -> str:
    """The file name of the last scene a page carries (the first is shown by default)."""
    text = page.read_text(encoding="utf-8")
    names = re.findall(r'"name": "[^"]*/([^"/]+\.toml)"', text)
    if not names:
        sys.exit(f"check_pages: {page.name} carries no scene")
    return names[-1]


ADDRESS_PROBE = """<script>
document.addEventListener('clothlab-ready', () => setTimeout(() => {
  const page = window.clothlabPage;
  const overlay = document.getElementById('overlay').textContent;
  const seen = { title: document.title, time: page.api.time(), dt: page.api.dt(), overlay,
                 play: document.getElementById('play').textContent,
                 shown: overlay.startsWith(`t = ${page.api.time().toFixed(3)} s`) };
  console.log('CLOTHLAB-ADDRESS ' + btoa(JSON.stringify(seen)));
}, 1000));
</script>"""


def check_address(page: pathlib.Path, scene: str, work: pathlib.Path) -> list:
    """The address names a scene and a time, and asks to wait there paused (as the lessons'
    screenshots are taken): a second later the page shows that scene at that time."""
    text = page.read_text(encoding="utf-8").replace("</body>", ADDRESS_PROBE + "\n</body>", 1)
    copy = work / ("address-" + page.name)
    copy.write_text(text, encoding="utf-8")
    url = f"{copy.resolve().as_uri()}#scene={scene}&t=0.5&paused"
    seen = drive(url, "CLOTHLAB-ADDRESS ", timeout=120) or {}
    # The game loop takes whole steps: the time reached is within a step below 0.5 s.
    time, dt = seen.get("time", -1), seen.get("dt", 0)
    ok = (0.5 - dt - 1e-9 <= time <= 0.5 + 1e-9 and seen.get("play") == "Play" and
          seen.get("title", "").startswith(scene + ":") and seen.get("shown"))
    print(f"  {'ok  ' if ok else 'FAIL'} {page.name}: #scene={scene}&t=0.5&paused waits at t = 0.5 s")
    return [] if ok else [f"{page.name}: #scene={scene}&t=0.5&paused shows {seen}"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("pages", nargs="+", type=pathlib.Path)
    args = parser.parse_args()
    test_script = (pathlib.Path(__file__).parent / "page_test.js").read_text(encoding="utf-8")
    problems = []
    with tempfile.TemporaryDirectory(prefix="clothlab-pages-") as work:
        for page in args.pages:
            problems += check(page, test_script, pathlib.Path(work))
        problems += check_without_simd(args.pages[0], pathlib.Path(work))
        # (A student page on the stubs stops at its first step: its address is the same code.)
        for page in (p for p in args.pages if not p.stem.endswith("-student")):
            problems += check_address(page, last_scene(page), pathlib.Path(work))
    for p in problems:
        print(p, file=sys.stderr)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
