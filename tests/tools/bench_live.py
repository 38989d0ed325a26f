#!/usr/bin/env python3
"""How fast a live page steps a scene against the native engine, measured in one run.

  python3 tests/tools/bench_live.py --clothlab build/clothlab \\
      --page build/pages/03-aerodynamics.html --scene tests/web/flag-32.toml

Natively: `clothlab run SCENE --no-html --threads 1`, REPEATS times (5 unless told). In the
page: headless Chromium opens a copy of the page, driven over the DevTools protocol; the scene
is loaded and warmed up for half a second of simulated time, then, REPEATS times, SECONDS of
simulated time in 1/60 s frames each way, drawing nothing (as the native run draws nothing):

  page    each frame advanced as the page advances it (live.js: the module's step, then the
          steps, the time and the energies read for the plot): the page's ms per step, to set
          against the native one;
  module  each frame the module's call alone (clothlab_advance): what the step costs inside the
          WebAssembly module; page minus module is the JavaScript around it.

With --float the page steps the scene in single precision (`[engine] precision = "float"` put
into its text) and two native runs take their turn each time, one in double as the scene is
written and one with `clothlab run --float`: the ratios are printed against both.

A native run and a repeat in the page take turns, so that both meet the same load. Each is
timed twice: in real time (the run's own "done: N steps in T s", the page's clock), and in
processor time (the native process's, its start and its frames written included; the page's
renderer main thread's, where the module runs), which a machine shared with other work disturbs
less. Prints every repeat, the medians and their ratios (page / native).

Then it runs the page as it runs for a student, two seconds of 1/60 s frames, each stepped and
then drawn: the ms a frame takes and the share of the drawing. Headless Chromium draws with
SwiftShader, WebGL on the processor, which shares the machine's cores with the stepping.

With --profile, the page's stepping runs once more under the DevTools protocol's sampling
profiler and the functions that took most of its time are listed (self time). The module names
its functions only when it is linked with them (the web build's CLOTHLAB_WEB_PROFILING=ON:
`cmake -DCLOTHLAB_WEB_PROFILING=ON build/web`); otherwise they show as wasm-function[N]."""

import argparse
import base64
import collections
import json
import os
import pathlib
import re
import shutil
import signal
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import time
import urllib.parse
import urllib.request

# Put into the copy of the page: the bench as a function the DevTools protocol calls.
BENCH = """<script>
(() => {
  let ok = true;
  const page = () => window.clothlabPage;
  const ways = {
    page: () => (ok = ok && page().advance(1 / 60)),
    module: () => (ok = ok && page().api.advance(1 / 60) === 0),
  };
  const problem = () => (ok ? null : page().message());
  // Loads the scene and warms it up for half a second: null, or what went wrong.
  window.clothlabBenchStart = (scene) => {
    page().setRunning(false);
    if (!page().load(scene.text, scene.name)) return page().message() || 'the scene did not load';
    page().setRunning(false);
    for (let k = 0; k < 30; ++k) ways.page();
    return problem();
  };
  // One repeat: `seconds` of simulated time one way (page or module), drawing nothing.
  window.clothlabBenchRepeat = (seconds, way) => {
    const api = page().api;
    const steps0 = api.steps(), t0 = performance.now();
    for (let k = 0; k < Math.round(seconds * 60); ++k) ways[way]();
    return {ms: performance.now() - t0, steps: api.steps() - steps0, error: problem()};
  };
  // Two seconds of frames, each stepped and then drawn.
  window.clothlabBenchDrawn = () => {
    const api = page().api, view = page().view;
    const drawn = {frames: 120, step_ms: 0, draw_ms: 0, worst: 0, view: view.kind};
    const steps0 = api.steps(), t0 = performance.now();
    for (let k = 0; k < drawn.frames; ++k) {
      const f0 = performance.now();
      ways.page();
      const f1 = performance.now();
      view.update();
      view.draw();
      const f2 = performance.now();
      drawn.step_ms += f1 - f0;
      drawn.draw_ms += f2 - f1;
      drawn.worst = Math.max(drawn.worst, f2 - f0);
    }
    drawn.ms = performance.now() - t0;
    drawn.steps = api.steps() - steps0;
    drawn.error = problem();
    return drawn;
  };
  // The page's stepping alone, for the profiler.
  window.clothlabStepFor = (seconds) => {
    for (let k = 0; k < Math.round(seconds * 60); ++k) ways.page();
    return page().api.steps();
  };
})();
</script>"""


class DevTools:
    """A client of the DevTools protocol over one WebSocket (RFC 6455), enough for calls and
    their answers: the standard library has no WebSocket client."""

    def __init__(self, url: str):
        parts = urllib.parse.urlparse(url)
        self.socket = socket.create_connection((parts.hostname, parts.port), timeout=600)
        key = base64.b64encode(os.urandom(16)).decode()
        self.socket.sendall((f"GET {parts.path} HTTP/1.1\r\nHost: {parts.netloc}\r\n"
                             "Upgrade: websocket\r\nConnection: Upgrade\r\n"
                             f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n")
                            .encode())
        self.stream = self.socket.makefile("rb")
        if b" 101 " not in self.stream.readline():
            sys.exit(f"bench_live: the browser refused the DevTools connection to {url}")
        while self.stream.readline() not in (b"\r\n", b""):
            pass
        self.last_id = 0

    def _send(self, opcode: int, data: bytes) -> None:
        header = bytearray([0x80 | opcode])
        if len(data) < 126:
            header.append(0x80 | len(data))
        elif len(data) < 1 << 16:
            header += bytes([0x80 | 126]) + struct.pack(">H", len(data))
        else:
            header += bytes([0x80 | 127]) + struct.pack(">Q", len(data))
        mask = os.urandom(4)
        self.socket.sendall(bytes(header) + mask + bytes(b ^ mask[k % 4] for k, b in enumerate(data)))

    def _exactly(self, n: int) -> bytes:
        data = self.stream.read(n)
        if len(data) != n:
            sys.exit("bench_live: the browser closed the DevTools connection")
        return data

    def _message(self) -> bytes:
        parts = []
        while True:
            first, second = self._exactly(2)
            n = second & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._exactly(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._exactly(8))[0]
            mask = self._exactly(4) if second & 0x80 else None
            payload = self._exactly(n)
            if mask:
                payload = bytes(b ^ mask[k % 4] for k, b in enumerate(payload))
            opcode = first & 0x0F
            if opcode == 8:
                sys.exit("bench_live: the browser closed the DevTools connection")
            if opcode == 9:  # ping
                self._send(10, payload)
                continue
            if opcode == 10:  # pong
                continue
            parts.append(payload)
            if first & 0x80:
                return b"".join(parts)

    def call(self, method: str, **params):
        self.last_id += 1
        self._send(1, json.dumps({"id": self.last_id, "method": method, "params": params}).encode())
        while True:
            answer = json.loads(self._message())
            if answer.get("id") == self.last_id:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error'].get('message')}")
                return answer["result"]

    def evaluate(self, expression: str):
        result = self.call("Runtime.evaluate", expression=expression, awaitPromise=True,
                           returnByValue=True)
        if "exceptionDetails" in result:
            sys.exit(f"bench_live: the page threw: {result['exceptionDetails']}")
        return result["result"].get("value")


def native(clothlab: str, scene: pathlib.Path, work: pathlib.Path, single: bool = False) -> dict:
    """ms per step of one native run (in float if `single`): real time as the run reports it, and
    the processor time of the whole process (its start and its frames written included)."""
    command = [clothlab, "run", str(scene), "--no-html", "--threads", "1", "--out",
               str(work / "native")] + (["--float"] if single else [])
    with subprocess.Popen(command, stdout=subprocess.PIPE, text=True) as run:
        out = run.stdout.read()
        _, status, usage = os.wait4(run.pid, 0)
        run.returncode = os.waitstatus_to_exitcode(status)
    found = re.search(r"done: (\d+) steps in ([0-9.]+) s", out)
    if run.returncode != 0 or not found:
        sys.exit(f"bench_live: {clothlab} run said no 'done: N steps in T s':\n{out}")
    steps = int(found.group(1))
    return {"real": 1000 * float(found.group(2)) / steps,
            "cpu": 1000 * (usage.ru_utime + usage.ru_stime) / steps}


def thread_seconds(pid: int) -> float:
    """The processor time of a process's main thread so far [s] (the scheduler's, in ns)."""
    try:
        return int(pathlib.Path(f"/proc/{pid}/task/{pid}/schedstat").read_text().split()[0]) / 1e9
    except OSError:
        return 0.0


def renderers(profile: pathlib.Path) -> list:
    """The browser's renderer processes (the page runs on the main thread of one of them)."""
    found = []
    for entry in pathlib.Path("/proc").iterdir():
        try:
            args = (entry / "cmdline").read_bytes()  # (a renderer's is one string)
        except OSError:
            continue
        if b"--type=renderer" in args and f"--user-data-dir={profile}".encode() in args:
            found.append(int(entry.name))
    return found


def in_float(text: str) -> str:
    """The scene's text with `[engine] precision = "float"` in it."""
    if re.search(r"^\s*precision\s*=", text, re.MULTILINE):
        sys.exit("bench_live: --float on a scene that sets its precision itself")
    header = re.search(r"^\[engine\][^\n]*\n", text, re.MULTILINE)
    if header:
        return text[:header.end()] + 'precision = "float"\n' + text[header.end():]
    return text + '\n[engine]\nprecision = "float"\n'


def open_page(page: pathlib.Path, scene: pathlib.Path, work: pathlib.Path, single: bool = False):
    """Headless Chromium on a copy of `page` with the bench in it: the browser's process and a
    DevTools connection to the page, once the engine has started and warmed up on `scene` (in
    float if `single`)."""
    work.mkdir(exist_ok=True)
    copy = work / page.name
    copy.write_text(page.read_text(encoding="utf-8").replace("</body>", BENCH + "\n</body>", 1),
                    encoding="utf-8")
    browser = next((b for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)),
                   None)
    if not browser:
        sys.exit("bench_live: no Chromium found (apt-get install -y chromium)")
    profile = work / "browser"
    command = [browser, "--headless", "--no-sandbox", "--disable-dev-shm-usage",
               "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--window-size=1200,800",
               "--remote-debugging-port=0", f"--user-data-dir={profile}", copy.resolve().as_uri()]
    # In a session of its own, so that stop() ends the browser's helper processes too.
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               start_new_session=True)
    try:
        tools = connect(process, profile)
        text = scene.read_text(encoding="utf-8")
        data = json.dumps({"name": str(scene), "text": in_float(text) if single else text})
        problem = tools.evaluate(f"clothlabBenchStart({data})")
        if problem:
            sys.exit(f"bench_live: the page could not run the scene: {problem}")
        return process, tools
    except BaseException:
        stop(process)
        raise


def stop(process: subprocess.Popen) -> None:
    """Ends the browser and every process it started."""
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    process.wait()


def connect(process: subprocess.Popen, profile: pathlib.Path) -> DevTools:
    """A DevTools connection to the browser's page, once the engine has started in it."""
    port_file = profile / "DevToolsActivePort"
    deadline = time.time() + 120
    while not port_file.exists() or not port_file.read_text().strip():
        if time.time() > deadline or process.poll() is not None:
            sys.exit("bench_live: Chromium did not open its DevTools port")
        time.sleep(0.2)
    port = int(port_file.read_text().split()[0])
    while True:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list") as answer:
            targets = [t for t in json.load(answer) if t.get("type") == "page"]
        if targets or time.time() > deadline:
            break
        time.sleep(0.2)
    if not targets:
        sys.exit("bench_live: Chromium shows no page")
    tools = DevTools(targets[0]["webSocketDebuggerUrl"])
    started = None
    while started is None:
        # The page may still be on its way from about:blank: its context is then destroyed
        # under the call, which is asked again.
        try:
            started = tools.evaluate("""new Promise((resolve) => {
      const wait = () => {
        const box = document.getElementById('message');
        if (window.clothlabPage) resolve(true);
        else if (box && box.className === 'error') resolve(box.textContent);
        else setTimeout(wait, 50);
      };
      wait();
    })""")
        except RuntimeError as error:
            if "context" not in str(error) or time.time() > deadline:
                sys.exit(f"bench_live: {error}")
            time.sleep(0.2)
    if started is not True:
        sys.exit(f"bench_live: the page did not start: {started}")
    return tools


def measure(clothlab: str, page: pathlib.Path, scene: pathlib.Path, seconds: float,
            repeats: int, work: pathlib.Path, single: bool = False) -> dict:
    """The native runs and the page's repeats, taken in turns (a native run, then a repeat in
    the page each way), so that both meet the same load on a shared machine. Each repeat in the
    page is timed by the page's clock (real time) and by the processor time of the renderer's
    main thread, where the page runs (the renderer whose main thread worked most)."""
    process, tools = open_page(page, scene, work, single)
    try:
        pids = renderers(work / "browser")
        natives, natives_float, repeated = [], [], {"page": [], "module": []}
        for _ in range(repeats):
            natives.append(native(clothlab, scene, work))
            if single:
                natives_float.append(native(clothlab, scene, work, single=True))
            for way in repeated:
                before = {pid: thread_seconds(pid) for pid in pids}
                result = tools.evaluate(f"clothlabBenchRepeat({seconds}, '{way}')")
                used = max(thread_seconds(pid) - before[pid] for pid in pids) if pids else 0.0
                if result["error"]:
                    sys.exit(f"bench_live: the page stopped: {result['error']}")
                repeated[way].append({"real": result["ms"] / result["steps"],
                                      "cpu": 1000 * used / result["steps"],
                                      "steps": result["steps"]})
        drawn = tools.evaluate("clothlabBenchDrawn()")
        if drawn["error"]:
            sys.exit(f"bench_live: the page stopped: {drawn['error']}")
        return {"natives": natives, "natives_float": natives_float, "repeats": repeated,
                "drawn": drawn}
    finally:
        stop(process)


def profile(page: pathlib.Path, scene: pathlib.Path, seconds: float, work: pathlib.Path,
            single: bool = False) -> None:
    """The page's stepping under the sampling profiler: the functions by self time."""
    process, tools = open_page(page, scene, work, single)
    try:
        tools.call("Profiler.enable")
        tools.call("Profiler.setSamplingInterval", interval=100)  # microseconds
        tools.call("Profiler.start")
        steps = tools.evaluate(f"clothlabStepFor({seconds})")
        result = tools.call("Profiler.stop")["profile"]
    finally:
        stop(process)
    nodes = {n["id"]: n for n in result["nodes"]}
    samples = collections.Counter(result["samples"])
    by_name = collections.Counter()
    for node_id, count in samples.items():
        frame = nodes[node_id]["callFrame"]
        name = frame["functionName"] or f"({pathlib.PurePath(frame['url']).name or 'anonymous'})"
        by_name[name] += count
    total = sum(by_name.values())
    idle = sum(by_name[n] for n in ("(idle)", "(program)", "(garbage collector)"))
    print(f"profile: {seconds} s of simulated time in 1/60 s frames ({steps} steps so far), "
          f"{total} samples of 100 us (idle, program and garbage collector {100 * idle / total:.1f} %)")
    for name, count in by_name.most_common(25):
        print(f"  {100 * count / total:5.1f} %  {name[:110]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--clothlab", required=True)
    parser.add_argument("--page", required=True, type=pathlib.Path)
    parser.add_argument("--scene", required=True, type=pathlib.Path)
    parser.add_argument("--seconds", type=float, default=5.0,
                        help="simulated time of each repeat in the page (default 5)")
    parser.add_argument("--repeats", type=int, default=5, help="runs of each (default 5)")
    parser.add_argument("--profile", action="store_true",
                        help="also profile the page's stepping and list where its time goes")
    parser.add_argument("--float", dest="single", action="store_true",
                        help="the page in single precision, against native in double and in float")
    args = parser.parse_args()
    if args.repeats < 1 or not args.seconds > 0:
        sys.exit("bench_live: --repeats must be at least 1 and --seconds above 0")
    with tempfile.TemporaryDirectory(prefix="clothlab-bench-live-") as work:
        found = measure(args.clothlab, args.page, args.scene, args.seconds, args.repeats,
                        pathlib.Path(work), args.single)
        if args.profile:
            profile(args.page, args.scene, args.seconds, pathlib.Path(work) / "profiled",
                    args.single)
    listed = lambda values: ", ".join(f"{v:.4f}" for v in values)
    steps = found["repeats"]["page"][0]["steps"]
    print(f"scene {args.scene}{', the page in float' if args.single else ''}: ms per step, "
          f"median of {args.repeats} (load average {os.getloadavg()[0]:.1f} at the end)")
    for clock, what in (("real", "real time"), ("cpu", "processor time")):
        native_runs = [r[clock] for r in found["natives"]]
        page_runs, module_runs = ([r[clock] for r in found["repeats"][w]] for w in ("page", "module"))
        native_ms, page_ms, module_ms = map(statistics.median, (native_runs, page_runs, module_runs))
        print(f" {what}:")
        print(f"  native  {native_ms:.4f}  of {listed(native_runs)} (clothlab run, one thread)")
        print(f"  page    {page_ms:.4f}  of {listed(page_runs)} (the page's advance, "
              f"{steps} steps each)")
        print(f"  module  {module_ms:.4f}  of {listed(module_runs)} (clothlab_advance alone; the "
              f"JavaScript around it {page_ms - module_ms:+.4f} ms a step)")
        print(f"  ratio   {page_ms / native_ms:.2f} page / native; the module alone "
              f"{module_ms / native_ms:.2f}")
        if args.single:
            float_runs = [r[clock] for r in found["natives_float"]]
            float_ms = statistics.median(float_runs)
            print(f"  native  {float_ms:.4f}  of {listed(float_runs)} (clothlab run --float, one "
                  "thread)")
            print(f"  ratio   {page_ms / float_ms:.2f} page / native in float; the module alone "
                  f"{module_ms / float_ms:.2f}")
    drawn = found["drawn"]
    frame_ms = drawn["ms"] / drawn["frames"]
    print(f"  frames  {frame_ms:.2f} ms per 1/60 s frame stepped and drawn with {drawn['view']} "
          f"(worst {drawn['worst']:.2f} ms; stepping {drawn['step_ms'] / drawn['frames']:.2f} ms, "
          f"{drawn['step_ms'] / drawn['steps']:.4f} ms a step; drawing "
          f"{drawn['draw_ms'] / drawn['frames']:.2f} ms): "
          f"{'keeps up with' if frame_ms <= 1000 / 60 else 'falls behind'} real time at 60 frames "
          "per second")


if __name__ == "__main__":
    main()
