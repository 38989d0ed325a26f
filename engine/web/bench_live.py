#!/usr/bin/env python3
"""How fast a live page steps a scene against the native engine, measured in one run.

  python3 engine/web/bench_live.py --clothlab build/clothlab \\
      --page build/pages/03-aerodynamics.html --scene tests/web/flag-32.toml

Natively: `clothlab run SCENE --no-html` on one thread, its "done: N steps in T s". In the page:
headless Chromium opens a copy of the page with a script that loads SCENE and advances it by
1/60 s frames for SECONDS of simulated time, timing each advance in real time (the browser's
clock, not a virtual one). Prints ms per step for both, their ratio, and whether the page keeps
up with real time at 60 frames per second."""

import argparse
import json
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

BENCH = """<script>
document.addEventListener('clothlab-ready', () => {
  const page = window.clothlabPage;
  const scene = SCENE_JSON;
  page.setRunning(false);
  if (!page.load(scene.text, scene.name)) {
    console.log('CLOTHLAB-BENCH ' + JSON.stringify({error: page.message()}));
    return;
  }
  page.setRunning(false);
  // Warm up for half a second of simulated time, then time SECONDS of 1/60 s frames.
  for (let k = 0; k < 30; ++k) page.advance(1 / 60);
  const steps0 = page.api.steps();
  let worst = 0, stepping = 0;
  const t0 = performance.now();
  const frames = Math.round(SECONDS * 60);
  for (let k = 0; k < frames; ++k) {
    const f0 = performance.now();
    page.advance(1 / 60);
    const f1 = performance.now();
    page.view.update();
    page.view.draw();
    stepping += f1 - f0;
    worst = Math.max(worst, performance.now() - f0);
  }
  const ms = performance.now() - t0;
  const steps = page.api.steps() - steps0;
  console.log('CLOTHLAB-BENCH ' + JSON.stringify({steps, ms, stepping, frames, worst, view: page.view.kind}));
});
</script>"""


def native(clothlab: str, scene: pathlib.Path, work: pathlib.Path) -> tuple:
    done = subprocess.run([clothlab, "run", str(scene), "--no-html", "--threads", "1", "--out",
                           str(work / "native")], capture_output=True, text=True, check=True)
    found = re.search(r"done: (\d+) steps in ([0-9.]+) s", done.stdout)
    steps, seconds = int(found.group(1)), float(found.group(2))
    return steps, seconds


def in_page(page: pathlib.Path, scene: pathlib.Path, seconds: float, work: pathlib.Path) -> dict:
    text = page.read_text(encoding="utf-8")
    data = json.dumps({"name": str(scene), "text": scene.read_text(encoding="utf-8")})
    data = data.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    script = BENCH.replace("SCENE_JSON", data).replace("SECONDS", str(seconds))
    copy = work / page.name
    copy.write_text(text.replace("</body>", script + "\n</body>", 1), encoding="utf-8")
    browser = next((b for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)),
                   None)
    if not browser:
        sys.exit("bench_live: no Chromium found (apt-get install -y chromium)")
    command = [browser, "--headless", "--no-sandbox", "--disable-dev-shm-usage",
               "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--window-size=1200,800",
               "--enable-logging=stderr", "--v=0", copy.resolve().as_uri()]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               text=True)
    deadline = time.time() + 300
    try:
        for line in process.stderr:
            found = re.search(r'CLOTHLAB-BENCH (\{.*?\})"', line)
            if found:
                return json.loads(found.group(1).replace('\\"', '"'))
            if time.time() > deadline:
                break
    finally:
        process.kill()
        process.wait()
    sys.exit("bench_live: the page reported nothing")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--clothlab", required=True)
    parser.add_argument("--page", required=True, type=pathlib.Path)
    parser.add_argument("--scene", required=True, type=pathlib.Path)
    parser.add_argument("--seconds", type=float, default=5.0, help="simulated time in the page")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="clothlab-bench-live-") as work:
        steps, seconds = native(args.clothlab, args.scene, pathlib.Path(work))
        page = in_page(args.page, args.scene, args.seconds, pathlib.Path(work))
    if "error" in page:
        sys.exit(f"bench_live: the page could not load the scene: {page['error']}")
    native_ms = 1000 * seconds / steps
    page_ms = page["stepping"] / page["steps"]
    frame_ms = page["ms"] / page["frames"]
    print(f"scene {args.scene}")
    print(f"  native  {native_ms:.4f} ms per step ({steps} steps in {seconds:.3f} s, one thread)")
    print(f"  page    {page_ms:.4f} ms per step ({page['steps']} steps in "
          f"{page['stepping'] / 1000:.3f} s of stepping)")
    print(f"  ratio   {page_ms / native_ms:.2f} (page / native)")
    print(f"  frames  {frame_ms:.2f} ms per 1/60 s frame, stepping and drawing with "
          f"{page['view']} (worst "
          f"{page['worst']:.2f} ms): {'keeps up with' if frame_ms <= 1000 / 60 else 'falls behind'}"
          f" real time at 60 frames per second")


if __name__ == "__main__":
    main()
