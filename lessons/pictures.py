#!/usr/bin/env python3
"""Renders the picture at the top of each lesson: its scene, run by clothlab, drawn by the
viewer page in headless Chromium, saved as lessons/NN-name/picture.png. The browser is given
no WebGL, so the page draws on its 2D canvas: the pictures stay the same whether or not the
build put three.js in the page (each lesson's live.png shows the WebGL drawing).

    cmake --build build --target pictures      (or: python3 lessons/pictures.py build/clothlab)
    python3 lessons/pictures.py build/clothlab 09-ropes-and-solids     (only the lessons named)
"""
import os
import shutil
import subprocess
import sys
import tempfile

# lesson folder -> (scene file, frame to show: a number, or -1 for the last)
PICTURES = {
    "01-particles-and-euler": ("two-bodies.toml", -1),
    "02-spring-dampers": ("hanging-cloth.toml", -1),
    "03-aerodynamics": ("flag.toml", 200),
    "04-bending-springs": ("drape-stiff.toml", -1),
    "05-ground-collision": ("cloth-on-sphere.toml", -1),
    "06-plasticity-and-tearing": ("storm-flag.toml", 25),
    "07-integrators": ("pendulum-cloth.toml", 10),
    "08-stability": ("stiff-sheet-implicit.toml", -1),
    "09-ropes-and-solids": ("jelly-cube.toml", 21),
    "10-collision-detection": ("towel-on-a-line.toml", 50),
    "11-game-loop": ("banner.toml", 240),
    "12-xpbd": ("stiff-curtain.toml", 120),
    "13-local-global": ("canvas-curtain.toml", 120),
    "14-vbd": ("stiff-sheet.toml", 120),
}


def main():
    if len(sys.argv) < 2 or any(name not in PICTURES for name in sys.argv[2:]):
        print(__doc__)
        return 2
    clothlab = os.path.abspath(sys.argv[1])
    chosen = sys.argv[2:] or list(PICTURES)
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        print("pictures: no chromium on this machine: sudo apt-get install -y chromium")
        return 1
    lessons = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(lessons)
    work = tempfile.mkdtemp(prefix="clothlab-pictures-")
    try:
        for lesson in chosen:
            scene, frame = PICTURES[lesson]
            out = os.path.join(work, lesson)
            page = os.path.join(out, "view.html")
            # Run from the repository's root, so the page names the scene as lessons/...
            subprocess.run([clothlab, "run", os.path.join("lessons", lesson, scene), "--out", out],
                           check=True, stdout=subprocess.DEVNULL, cwd=root)
            picture = os.path.join(lessons, lesson, "picture.png")
            shown = 10**6 if frame < 0 else frame  # the viewer clamps to the last frame
            subprocess.run(
                [browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-3d-apis",
                 "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync",
                 f"--user-data-dir={os.path.join(work, 'profile')}", "--window-size=720,420",
                 "--hide-scrollbars", "--virtual-time-budget=3000", f"--screenshot={picture}",
                 f"file://{page}?frame={shown}&still"],
                check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=120)
            print(f"pictures: {os.path.relpath(picture)} ({scene})")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
