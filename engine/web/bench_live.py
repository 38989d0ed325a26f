#!/usr/bin/env python3
"""How fast a live page steps a scene against the native engine, measured in one run.

  python3 engine/web/bench_live.py --clothlab build/clothlab \\
      --page build/pages/03-aerodynamics.html --scene tests/web/flag-32.toml

Natively: `clothlab run SCENE --no-html` on one thread, REPEATS times, each run's "done: N steps
in T s". In the page: headless Chromium opens a copy of the page with a script that loads SCENE,
warms it up for half a second of simulated time, then

  1. steps it: REPEATS times SECONDS of simulated time in 1/60 s frames, drawing nothing, as the
     native run draws nothing, timing each advance with the browser's clock (real time, not a
     virtual one): the page's ms per step, to set against the native one;
  2. runs it as a page does, two seconds of 1/60 s frames, each one stepped and then drawn:
     the ms a frame takes, and whether the page keeps up with real time at 60 frames a second.

Headless Chromium draws with SwiftShader, WebGL on the processor: its drawing shares the
machine's cores with the stepping, so the ms per step of part 2 (printed too) is the step
slowed by the software renderer, which a graphics card would take off the processor.
Prints every repeat, the medians and their ratio (page / native)."""

import argparse
import json
import pathlib
import re
import shutil
import statistics
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
  let ok = true;
  const advance = () => (ok = ok && page.advance(1 / 60));
  for (let k = 0; k < 30; ++k) advance();  // warm-up: half a second
  // 1. Stepping alone.
  const stepping = [];
  for (let r = 0; r < REPEATS; ++r) {
    const steps0 = page.api.steps();
    let ms = 0;
    for (let k = 0; k < Math.round(SECONDS * 60); ++k) {
      const f0 = performance.now();
      advance();
      ms += performance.now() - f0;
    }
    stepping.push({steps: page.api.steps() - steps0, ms});
  }
  // 2. Frames stepped and drawn.
  const frames = 120, steps0 = page.api.steps();
  let worst = 0, step_ms = 0;
  const t0 = performance.now();
  for (let k = 0; k < frames; ++k) {
    const f0 = performance.now();
    advance();
    step_ms += performance.now() - f0;
    page.view.update();
    page.view.draw();
    worst = Math.max(worst, performance.now() - f0);
  }
  const drawn = {frames, ms: performance.now() - t0, steps: page.api.steps() - steps0, step_ms,
                 worst, view: page.view.kind};
  console.log('CLOTHLAB-BENCH ' + JSON.stringify({stepping, drawn, error: ok ? null : page.message()}));
});
</script>"""


def native(clothlab: str, scene: pathlib.Path, work: pathlib.Path) -> float:
    """ms per step of one native run."""
    done = subprocess.run([clothlab, "run", str(scene), "--no-html", "--threads", "1", "--out",
                           str(work / "native")], capture_output=True, text=True, check=True)
    found = re.search(r"done: (\d+) steps in ([0-9.]+) s", done.stdout)
    if not found:
        sys.exit(f"bench_live: {clothlab} run said no 'done: N steps in T s':\n{done.stdout}")
    return 1000 * float(found.group(2)) / int(found.group(1))


def in_page(page: pathlib.Path, scene: pathlib.Path, seconds: float, repeats: int,
            work: pathlib.Path) -> dict:
    text = page.read_text(encoding="utf-8")
    data = json.dumps({"name": str(scene), "text": scene.read_text(encoding="utf-8")})
    data = data.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    script = (BENCH.replace("SCENE_JSON", data).replace("SECONDS", str(seconds))
              .replace("REPEATS", str(repeats)))
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
    parser.add_argument("--seconds", type=float, default=5.0,
                        help="simulated time of each repeat in the page (default 5)")
    parser.add_argument("--repeats", type=int, default=3, help="runs of each (default 3)")
    args = parser.parse_args()
    if args.repeats < 1 or not args.seconds > 0:
        sys.exit("bench_live: --repeats must be at least 1 and --seconds above 0")
    with tempfile.TemporaryDirectory(prefix="clothlab-bench-live-") as work:
        natives = [native(args.clothlab, args.scene, pathlib.Path(work))
                   for _ in range(args.repeats)]
        page = in_page(args.page, args.scene, args.seconds, args.repeats, pathlib.Path(work))
    if "stepping" not in page:
        sys.exit(f"bench_live: the page could not load the scene: {page['error']}")
    if page.get("error"):
        sys.exit(f"bench_live: the page stopped: {page['error']}")
    pages = [r["ms"] / r["steps"] for r in page["stepping"]]
    native_ms, page_ms = statistics.median(natives), statistics.median(pages)
    drawn = page["drawn"]
    frame_ms = drawn["ms"] / drawn["frames"]
    listed = lambda values: ", ".join(f"{v:.4f}" for v in values)
    print(f"scene {args.scene}")
    print(f"  native  {native_ms:.4f} ms per step, median of {listed(natives)} "
          f"(clothlab run, one thread)")
    print(f"  page    {page_ms:.4f} ms per step, median of {listed(pages)} "
          f"(stepping alone, {page['stepping'][0]['steps']} steps each)")
    print(f"  ratio   {page_ms / native_ms:.2f} (page / native)")
    print(f"  frames  {frame_ms:.2f} ms per 1/60 s frame stepped and drawn with {drawn['view']} "
          f"(worst {drawn['worst']:.2f} ms; the step {drawn['step_ms'] / drawn['steps']:.4f} ms "
          f"while drawing): {'keeps up with' if frame_ms <= 1000 / 60 else 'falls behind'} "
          f"real time at 60 frames per second")


if __name__ == "__main__":
    main()
