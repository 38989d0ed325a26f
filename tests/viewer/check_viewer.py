#!/usr/bin/env python3
"""Opens a run's viewer page in headless Chromium and checks its screenshots.

  1. The cloth is drawn: the picture of the first frame is not a blank canvas.
  2. It moves: a later frame's picture differs from the first.

Both on the 2D canvas (a browser without WebGL) and, with --webgl (the build put three.js in the
page), with WebGL through the live pages' renderer, which the page must then say it uses.

Exit 0 when both hold, 1 when one fails, 77 (ctest's "skipped") when no Chromium is installed,
unless CLOTHLAB_REQUIRE_BROWSER=1 (as in CI), which makes a missing browser a failure.
"""
import argparse
import os
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
    """What the page says it draws with: "webgl", or "2d" when it says nothing."""
    dom = subprocess.run(
        browser_command(browser, profile, flags) + ["--dump-dom", f"file://{os.path.abspath(page)}?frame=0"],
        check=True, capture_output=True, text=True, timeout=120).stdout
    return "webgl" if 'data-renderer="webgl"' in dom else "2d"


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


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--clothlab", required=True)
    parser.add_argument("--scene", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--webgl", action="store_true",
                        help="the page carries three.js: check its WebGL drawing too")
    args = parser.parse_args()

    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        print("no chromium on this machine: sudo apt-get install -y chromium")
        return 1 if os.environ.get("CLOTHLAB_REQUIRE_BROWSER") == "1" else 77

    os.makedirs(args.work, exist_ok=True)
    run = os.path.join(args.work, "run")  # the run's own folder; the screenshots beside it
    page = os.path.join(run, "view.html")
    subprocess.run([args.clothlab, "run", args.scene, "--out", run, "--html", page],
                   check=True, stdout=subprocess.DEVNULL)
    profile = tempfile.mkdtemp(prefix="clothlab-chromium-")
    ok = True
    try:
        passes = [("2D canvas", NO_WEBGL, BACKGROUND, "2d")]
        if args.webgl:
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
    finally:
        shutil.rmtree(profile, ignore_errors=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
