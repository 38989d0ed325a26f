#!/usr/bin/env python3
"""Opens a run's viewer page in headless Chromium and checks its screenshots.

  1. The cloth is drawn: the picture of the first frame is not a blank canvas.
  2. It moves: a later frame's picture differs from the first.

Both drawn by the live pages' renderer (engine/web/render.js), which the page must say it uses:
with its painter on a 2D canvas (a browser without WebGL) and, with --webgl (the build put
three.js in the page), with WebGL.

With --blowup SCENE (a scene the guard stops), also:

  3. The page of a run the guard stopped says so: the guard's message, its step and particle,
     and its last frame marked as the last before the stop (read from the page's DOM as the
     browser left it).

Exit 0 when all hold, 1 when one fails, 77 (ctest's "skipped") when no Chromium is installed,
unless CLOTHLAB_REQUIRE_BROWSER=1 (as in CI), which makes a missing browser a failure.
"""
import argparse
import html
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

BACKGROUND = (0xF4, 0xF4, 0xF1)  # the page's background colour, viewer.html
WEBGL_BACKGROUND = (0xDF, 0xE6, 0xEC)  # the renderer's, engine/web/render.js
# Chromium with WebGL on the CPU (SwiftShader), or with no GPU and so no WebGL.
WEBGL = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
NO_WEBGL = ["--disable-gpu", "--disable-3d-apis"]
WIDTH, HEIGHT = 800, 600
BAR = 64  # the control bar at the bottom of the page [px]


def read_png(path):
    """Returns (width, height, rows of RGB tuples) of an 8-bit RGB or RGBA PNG."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert depth == 8 and colour in (2, 6) and interlace == 0, f"unexpected PNG format {header}"
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):  # undo the PNG row filter
            a = line[x - channels] if x >= channels else 0
            b = previous[x]
            c = previous[x - channels] if x >= channels else 0
            if kind == 1:
                line[x] = (line[x] + a) & 255
            elif kind == 2:
                line[x] = (line[x] + b) & 255
            elif kind == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        previous = line
    return width, height, rows


def browser_command(browser, profile, flags):
    return [browser, "--headless", "--no-sandbox", *flags, "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            f"--user-data-dir={profile}", f"--window-size={WIDTH},{HEIGHT}", "--hide-scrollbars",
            "--virtual-time-budget=3000"]


def screenshot(browser, page, frame, out, profile, flags):
    subprocess.run(
        browser_command(browser, profile, flags) +
        [f"--screenshot={out}", f"file://{os.path.abspath(page)}?frame={frame}"],
        check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=120)
    return read_png(out)


def renderer_of(browser, page, profile, flags):
    """What the page says it draws with: the kind of the renderer's view ("webgl" or "2d")."""
    dom = subprocess.run(
        browser_command(browser, profile, flags) + ["--dump-dom", f"file://{os.path.abspath(page)}?frame=0"],
        check=True, capture_output=True, text=True, timeout=120).stdout
    found = re.search(r'data-renderer="([a-z0-9]+)"', dom)
    return found.group(1) if found else "nothing (no renderer)"


def check_pictures(first, later, background, what):
    def far_from(pixel, ref):
        return sum(abs(p - r) for p, r in zip(pixel, ref)) > 40

    width, height, rows = first
    view = [(x, y) for y in range(0, height - BAR, 2) for x in range(0, width, 2)]
    drawn = sum(far_from(rows[y][x], background) for x, y in view)
    changed = sum(far_from(rows[y][x], later[2][y][x]) for x, y in view)
    share_drawn, share_changed = drawn / len(view), changed / len(view)
    print(f"{what}: first frame: {100 * share_drawn:.1f} % of the view is drawn; "
          f"last frame differs from it in {100 * share_changed:.1f} % of the view")
    ok = True
    if share_drawn < 0.02:
        print(f"FAIL: {what}: the first frame looks blank: the cloth was not drawn")
        ok = False
    if share_changed < 0.01:
        print(f"FAIL: {what}: the last frame looks like the first: nothing moved on screen")
        ok = False
    return ok


def check_stopped_page(browser, clothlab, scene, work, profile):
    """Runs `scene`, which the guard must stop, and reads its page's DOM at the last frame."""
    run = os.path.join(work, "blowup")
    page = os.path.join(run, "view.html")
    result = subprocess.run([clothlab, "run", scene, "--out", run, "--html", page, "--force"],
                            capture_output=True, text=True)
    found = re.search(r"(blew up|ran away) at step (\d+) .*?particle (\d+)", result.stderr)
    if result.returncode == 0 or not found:
        print(f"FAIL: {scene} was to be stopped by the guard; exit {result.returncode}, "
              f"stderr: {result.stderr.strip()}")
        return False
    kind, step, particle = found.groups()
    dom = subprocess.run(
        browser_command(browser, profile, NO_WEBGL) +
        ["--dump-dom", f"file://{os.path.abspath(page)}?frame={10**6}"],
        check=True, capture_output=True, text=True, timeout=120).stdout
    box = re.search(r'<div id="stopped"[^>]*>(.*?)</div>', dom, re.S)
    clock = re.search(r'<span id="clock">(.*?)</span>', dom, re.S)
    text = html.unescape(box.group(1)) if box else ""
    shown = box is not None and "display: block" in box.group(0)
    checks = [
        ("the page shows the guard's message", shown and f"{kind} at step {step}" in text),
        (f"it names the step ({step}) and the particle ({particle})",
         f"at step {step}, at particle {particle};" in text),
        ("its last frame is marked as the last before the stop",
         clock is not None and "(stopped here)" in clock.group(1)),
    ]
    ok = True
    for what, good in checks:
        print(f"{'ok' if good else 'FAIL'}: stopped run: {what}")
        ok = ok and good
    if not ok:
        print(f"  the page's box: {text!r}; its clock: {clock.group(1) if clock else None!r}")
    return ok


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--clothlab", required=True)
    parser.add_argument("--scene", help="a scene to run and check the pictures of")
    parser.add_argument("--work", required=True)
    parser.add_argument("--webgl", action="store_true",
                        help="the page carries three.js: check its WebGL drawing too")
    parser.add_argument("--blowup", help="a scene the guard stops: check that its page says so")
    args = parser.parse_args()

    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        print("no chromium on this machine: sudo apt-get install -y chromium")
        return 1 if os.environ.get("CLOTHLAB_REQUIRE_BROWSER") == "1" else 77

    os.makedirs(args.work, exist_ok=True)
    run = os.path.join(args.work, "run")  # the run's own folder; the screenshots beside it
    page = os.path.join(run, "view.html")
    if args.scene:
        subprocess.run([args.clothlab, "run", args.scene, "--out", run, "--html", page],
                       check=True, stdout=subprocess.DEVNULL)
    profile = tempfile.mkdtemp(prefix="clothlab-chromium-")
    ok = True
    try:
        passes = [("2D canvas", NO_WEBGL, BACKGROUND, "2d")] if args.scene else []
        if args.webgl and args.scene:
            passes.append(("WebGL", WEBGL, WEBGL_BACKGROUND, "webgl"))
        for what, flags, background, expected in passes:
            renderer = renderer_of(browser, page, profile, flags)
            if renderer != expected:
                print(f"FAIL: {what}: the page draws with {renderer}, not {expected}")
                ok = False
                continue
            stem = os.path.join(args.work, expected)
            first = screenshot(browser, page, 0, stem + "-first.png", profile, flags)
            later = screenshot(browser, page, 10**6, stem + "-last.png", profile, flags)
            ok = check_pictures(first, later, background, what) and ok
        if args.blowup:
            ok = check_stopped_page(browser, args.clothlab, args.blowup, args.work, profile) and ok
    finally:
        shutil.rmtree(profile, ignore_errors=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
