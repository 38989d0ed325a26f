#!/usr/bin/env python3
"""Takes the screenshot of each lesson's live page shown in its README: the page opened in
headless Chromium at a moment of its scene, saved as lessons/NN-name/live.png.

    cmake --build build --target web && python3 lessons/live_pictures.py build/pages
    python3 lessons/live_pictures.py build/pages 03-aerodynamics     (only the lessons named)
"""
import pathlib
import shutil
import subprocess
import sys

# lesson folder -> (scene file, simulated time to show [s])
SHOTS = {
    "01-particles-and-euler": ("two-bodies.toml", 2.0),
    "02-spring-dampers": ("hanging-cloth.toml", 1.5),
    "03-aerodynamics": ("flag.toml", 2.0),
    "04-bending-springs": ("drape-stiff.toml", 1.5),
    "05-ground-collision": ("cloth-on-sphere.toml", 2.0),
    "06-plasticity-and-tearing": ("storm-flag.toml", 1.0),
    "07-integrators": ("pendulum-cloth.toml", 1.0),
    "08-stability": ("stiff-sheet-implicit.toml", 1.0),
    "09-ropes-and-solids": ("jelly-cube.toml", 1.0),
    "10-collision-detection": ("towel-on-a-line.toml", 1.5),
    "11-game-loop": ("banner.toml", 2.0),
    "12-xpbd": ("stiff-curtain.toml", 1.0),
    "13-local-global": ("canvas-curtain.toml", 1.0),
    "14-vbd": ("stiff-sheet.toml", 1.0),
}


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    pages = pathlib.Path(sys.argv[1])
    only = sys.argv[2:]
    lessons = pathlib.Path(__file__).resolve().parent
    browser = next((b for b in ("chromium", "chromium-browser") if shutil.which(b)), None)
    if not browser:
        sys.exit("live_pictures: needs chromium (sudo apt-get install -y chromium)")
    for lesson, (scene, t) in SHOTS.items():
        if only and lesson not in only:
            continue
        page = pages / f"{lesson}.html"
        out = lessons / lesson / "live.png"
        url = f"{page.resolve().as_uri()}#scene={scene}&t={t}&paused"
        subprocess.run([browser, "--headless", "--no-sandbox", "--use-angle=swiftshader",
                        "--enable-unsafe-swiftshader", "--hide-scrollbars",
                        "--window-size=1280,720", "--virtual-time-budget=3000",
                        f"--screenshot={out}", url],
                       check=True, capture_output=True, timeout=300)
        print(f"  {out.relative_to(lessons.parent)}: {scene} at t = {t} s")


if __name__ == "__main__":
    main()
