// live.js: the live lesson page. It runs the engine module (engine/web/live.cpp) on the
// lesson's scenes, draws the cloth with three.js, and turns the page's controls into edits of
// the scene: a slider is a number of the scene's TOML, changed while the motion goes on.
'use strict';

(function () {
  const lesson = JSON.parse(document.getElementById('lesson-data').textContent);
  const $ = (id) => document.getElementById(id);
  const kStatus = ['ok', 'a scene error', 'the guard stopped the run', 'an exercise to do', 'an error'];

  // --- The engine -------------------------------------------------------------------------
  let module = null;
  let api = null;
  let sceneName = '';
  let sceneText = '';   // the scene as it runs now (sliders change it)
  let loadedText = '';  // the scene as it was loaded or last run from the editor
  let running = true;
  let failed = false;
  let parameters = [];  // the numbers of the scene (clothlab_parameters)
  const pageTitle = document.title;  // the lesson's; the scene's name goes before it
  const stats = { steps: 0, stepMs: 0, frames: 0 };

  function bind(m) {
    const f = (name, ret, args) => m.cwrap(name, ret, args);
    return {
      load: f('clothlab_load', 'number', ['string', 'string']),
      reload: f('clothlab_reload', 'number', ['string', 'string']),
      message: f('clothlab_message', 'string', []),
      parameters: f('clothlab_parameters', 'string', []),
      edit: f('clothlab_edit', 'number', ['string', 'string', 'string']),
      integrators: f('clothlab_integrators', 'string', []),
      advance: f('clothlab_advance', 'number', ['number']),
      time: f('clothlab_time', 'number', []),
      dt: f('clothlab_dt', 'number', []),
      steps: f('clothlab_steps', 'number', []),
      kinetic: f('clothlab_kinetic', 'number', []),
      potential: f('clothlab_potential', 'number', []),
      particles: f('clothlab_particles', 'number', []),
      positions: f('clothlab_positions', 'number', []),
      statePositions: f('clothlab_state_positions', 'number', []),
      triangleCount: f('clothlab_triangle_count', 'number', []),
      triangles: f('clothlab_triangles', 'number', []),
      springCount: f('clothlab_spring_count', 'number', []),
      springs: f('clothlab_springs', 'number', []),
      strains: f('clothlab_strains', 'number', []),
      method: f('clothlab_method', 'string', []),
      colliders: f('clothlab_colliders', 'string', []),
      isPinned: f('clothlab_is_pinned', 'number', ['number']),
      grab: f('clothlab_grab', 'number', ['number']),
      drag: f('clothlab_drag', 'number', ['number', 'number', 'number', 'number']),
      release: f('clothlab_release', 'number', ['number']),
    };
  }

  function showMessage(text, kind) {
    const box = $('message');
    box.textContent = text;
    box.className = text ? kind : '';
  }

  // A status other than ok stops the motion and shows the engine's message.
  function check(status) {
    if (status === 0) return true;
    failed = true;
    setRunning(false);
    showMessage(`${kStatus[status] || 'an error'}:\n${api.message()}`, 'error');
    return false;
  }

  // An engine as the renderer sees it (render.js): views into the module's memory, made anew
  // at each call since the memory may grow.
  function sourceOf(m, a) {
    return {
      count: () => a.particles(),
      positions: () => new Float64Array(m.HEAPF64.buffer, a.positions(), 3 * a.particles()),
      triangles: () => new Int32Array(m.HEAP32.buffer, a.triangles(), 3 * a.triangleCount()),
      springs: () => new Int32Array(m.HEAP32.buffer, a.springs(), 2 * a.springCount()),
      isPinned: (i) => a.isPinned(i),
      strains: () => new Float64Array(m.HEAPF64.buffer, a.strains(), a.particles()),
      colliders: () => JSON.parse(a.colliders()),
    };
  }
  let source = null;  // this page's engine, as sourceOf() gives it

  // The positions as the last step left them (not as drawn, between the last two steps).
  function statePositions(m, a) {
    return new Float64Array(m.HEAPF64.buffer, a.statePositions(), 3 * a.particles());
  }

  function positions() {
    return source.positions();
  }

  // --- Loading a scene --------------------------------------------------------------------
  function load(text, name) {
    sceneName = name;
    failed = false;
    showMessage('', '');
    const status = api.load(text, name);
    $('editor').value = text;
    twin.load(text, name, status);
    if (!check(status)) return false;
    sceneText = text;
    loadedText = text;
    document.title = `${name.split('/').pop()}: ${pageTitle}`;
    parameters = JSON.parse(api.parameters());
    stats.steps = 0;
    energy.clear();
    buildSliders();
    readIntegrator();
    rebuildView(false);
    setRunning(true);
    return true;
  }

  function rebuildView(keepCamera) {
    view.rebuild(twin.on ? [source, twin.source] : [source], keepCamera);
  }

  // Changes the number at `path` to `value` and goes on with the motion.
  function setParameter(path, value) {
    const text = editText(sceneText, path, value);
    if (text === null) return false;
    const status = api.reload(text, sceneName);
    if (status !== 0) {
      // The value is refused: say why. The engine kept the scene that ran, untouched (a scene
      // it cannot read replaces nothing), and the sliders go back to its numbers.
      showMessage(`${path} = ${value}: ${api.message()}`, 'error');
      buildSliders();
      return false;
    }
    showMessage('', '');
    failed = false;
    sceneText = text;
    $('editor').value = text;
    parameters = JSON.parse(api.parameters());
    twin.reload(text, sceneName);
    rebuildView(true);
    return true;
  }

  function editText(text, path, value) {
    const pointer = api.edit(text, path, String(value));
    if (!pointer) {
      showMessage(api.message(), 'error');
      return null;
    }
    return module.UTF8ToString(pointer);
  }

  // --- Controls ---------------------------------------------------------------------------
  function setRunning(on) {
    running = on && !failed;
    $('play').textContent = running ? 'Pause' : 'Play';
  }

  const formatValue = ClothlabRender.formatValue;

  // A slider over [value / 10, value * 10] on a log scale for a positive number; linear over
  // a symmetric range for one that may be negative or is 0. Either is cut to the values the
  // scene reader accepts (p.min, p.max: null where there is no bound); null when that leaves
  // no room to move.
  function sliderScale(p) {
    const v = p.value;
    const lo = p.min ?? -Infinity, hi = p.max ?? Infinity;
    if (v > 0 && !p.name.endsWith(']')) {
      const a = Math.max(v / 10, lo), b = Math.min(v * 10, hi);
      if (!(a > 0 && b > a)) return null;
      const la = Math.log(a), lb = Math.log(b);
      return { to: (s) => Math.exp(la + (lb - la) * s), from: (x) => (Math.log(x) - la) / (lb - la) };
    }
    const span = Math.max(Math.abs(v) * 3, 1);
    const a = Math.max(-span, lo), b = Math.min(span, hi);
    if (!(b > a)) return null;
    return { to: (s) => a + (b - a) * s, from: (x) => (x - a) / (b - a) };
  }

  // A slider's table and label: `aerodynamics.wind[2]` is `wind z` under `[aerodynamics]` (a
  // vector of three is x, y, z), `springs.ks` is `ks` under `[springs]`, `plane[1].e` is `e`
  // under `[[plane]] #2`.
  function sliderHeading(name) {
    const head = name.slice(0, name.indexOf('.'));
    const repeated = /^(\w+)\[(\d+)\]$/.exec(head);
    return repeated ? `[[${repeated[1]}]] #${Number(repeated[2]) + 1}` : `[${head}]`;
  }
  function sliderLabel(name) {
    const key = name.slice(name.lastIndexOf('.') + 1);
    const element = /^(.*)\[(\d)\]$/.exec(key);
    if (!element) return key;
    const vector = name.slice(0, name.lastIndexOf('['));
    const size = parameters.filter((q) => q.name.startsWith(`${vector}[`)).length;
    return size === 3 ? `${element[1]} ${'xyz'[Number(element[2])]}` : key;
  }

  function buildSliders() {
    const box = $('sliders');
    box.textContent = '';
    let table = '';
    for (const p of parameters) {
      const scale = sliderScale(p);
      if (!scale) continue;
      const heading = sliderHeading(p.name);
      if (heading !== table) {
        table = heading;
        const title = document.createElement('div');
        title.className = 'slider-table';
        title.textContent = heading;
        box.append(title);
      }
      const row = document.createElement('label');
      row.className = 'slider';
      const name = document.createElement('span');
      name.textContent = sliderLabel(p.name);
      name.title = p.name;
      const input = document.createElement('input');
      input.type = 'range';
      input.min = 0;
      input.max = 1000;
      input.dataset.name = p.name;
      const out = document.createElement('output');
      input.value = Math.round(1000 * scale.from(p.value));
      out.textContent = formatValue(p.value);
      input.addEventListener('input', () => {
        const value = Number(scale.to(input.value / 1000).toPrecision(4));
        out.textContent = formatValue(value);
        setParameter(p.name, value);
      });
      row.append(name, input, out);
      box.append(row);
    }
    if (!box.children.length) box.textContent = 'This scene has no physical parameters to vary.';
  }

  function readIntegrator() {
    $('dt').value = api.dt();
    $('integrator').value = api.method();
  }

  function setupControls() {
    for (const s of lesson.scenes) {
      const option = document.createElement('option');
      option.value = s.name;
      option.textContent = s.name.split('/').pop();
      $('scene').append(option);
    }
    for (const name of JSON.parse(api.integrators())) {
      const option = document.createElement('option');
      option.textContent = name;
      $('integrator').append(option);
    }
    $('scene').addEventListener('change', () => {
      const s = lesson.scenes.find((x) => x.name === $('scene').value);
      load(s.text, s.name);
    });
    $('play').addEventListener('click', () => setRunning(!running));
    $('step').addEventListener('click', () => {
      setRunning(false);
      advance(api.dt());
    });
    $('reset').addEventListener('click', () => load(loadedText, sceneName));
    $('integrator').addEventListener('change', () =>
      setParameter('integrator.method', `"${$('integrator').value}"`));
    $('dt').addEventListener('change', () => {
      const dt = Number($('dt').value);
      if (!(dt > 0)) return showMessage('dt must be a number > 0 [s]', 'error');
      setParameter('integrator.dt', dt);
    });
    const runEdited = () => {
      const text = $('editor').value;
      if (load(text, sceneName)) showMessage('', '');
    };
    $('run-edited').addEventListener('click', runEdited);
    $('editor').addEventListener('keydown', (e) => {
      if (e.key === 'Enter' && (e.ctrlKey || e.metaKey)) {
        e.preventDefault();
        runEdited();
      }
    });
  }

  // --- Stepping ---------------------------------------------------------------------------
  function advance(frameTime) {
    const before = api.steps();
    const t0 = performance.now();
    const status = api.advance(frameTime);
    const ms = performance.now() - t0;
    const taken = api.steps() - before;
    if (taken > 0) {
      stats.steps += taken;
      // A running mean over about a second of steps.
      const w = Math.min(1, taken / 500);
      stats.stepMs = stats.stepMs === 0 ? ms / taken : (1 - w) * stats.stepMs + w * (ms / taken);
    }
    twin.advance(frameTime, status);
    if (!check(status)) return false;
    energy.add(api.time(), api.kinetic(), api.potential());
    return true;
  }

  // --- Energy plot ------------------------------------------------------------------------
  const energy = {
    t: [], k: [], u: [],
    clear() { this.t = []; this.k = []; this.u = []; },
    add(t, k, u) {
      this.t.push(t); this.k.push(k); this.u.push(u);
      if (this.t.length > 600) { this.t.shift(); this.k.shift(); this.u.shift(); }
    },
    draw() { ClothlabRender.plotEnergy($('energy'), this.t, this.k, this.u); },
  };

  // --- Drawing ----------------------------------------------------------------------------
  const view = ClothlabRender.makeView($('canvas'), Array.from(document.querySelectorAll('.pane-label')));

  function setupDisplay() {
    const settings = view.settings;
    $('strain').addEventListener('change', () => { settings.strain = $('strain').checked; view.update(); });
    $('strain-scale').addEventListener('change', () => { settings.strainScale = Number($('strain-scale').value); view.update(); });
    $('show-springs').addEventListener('change', () => { settings.springs = $('show-springs').checked; });
  }

  // --- Side by side with the reference ----------------------------------------------------
  // A student page carries the reference build too (createClothlabReference). Side by side, it
  // runs the same scene with the same slider changes, frame times and mouse, and the page marks
  // the first frame where any particle of the student's cloth is farther than the tolerance
  // from the reference's: the frame, its time, the particle and the distance. Frames are
  // compared after each advance, on the positions the last step left.
  const twin = {
    engine: null, api: null, source: null, on: false,
    tolerance: 1e-9, frames: 0, worst: 0, first: null,

    // Starts a second engine from `factory`, then runs it beside this page's from the start
    // of the scene as it is now.
    start(factory) {
      const begin = (m) => {
        this.engine = m;
        this.api = bind(m);
        this.source = sourceOf(m, this.api);
        this.on = true;
        load($('editor').value, sceneName);  // the scene as shown, from its start
      };
      return this.engine ? Promise.resolve(begin(this.engine)) : factory().then(begin);
    },
    stop() {
      this.on = false;
      this.first = null;
      rebuildView(true);
      this.show();
    },
    // Reads the scene the page has just read with `status`: the student's code may have stopped
    // while building it (a stub the construction calls), which is then the first difference.
    load(text, name, status) {
      this.frames = 0;
      this.worst = 0;
      this.first = null;
      if (!this.on) return;
      const twinStatus = this.api.load(text, name);
      if (status !== 0 && twinStatus === 0) {
        this.first = { frame: 0, time: 0, text: `your code stopped (${kStatus[status]}): ${api.message()}` };
      } else if (status === 0) {
        this.mirror(twinStatus, 'read the scene');
      }
      this.show();
    },
    reload(text, name) {
      if (this.on) this.mirror(this.api.reload(text, name), 'read the scene again');
    },
    // The reference failing where the student's code did not is worth saying (a scene that
    // blows up does so in both).
    mirror(status, what) {
      if (status === 0 || this.first) return status === 0;
      this.first = { frame: this.frames, time: api.time(), text: `the reference could not ${what}: ${this.api.message()}` };
      this.show();
      return false;
    },
    advance(frameTime, status) {
      if (!this.on) return;
      const twinStatus = this.api.advance(frameTime);
      this.frames += 1;
      if (this.first) return;
      if (status !== 0 || twinStatus !== 0) {
        this.first = {
          frame: this.frames, time: api.time(),
          text: status !== 0 ? `your code stopped (${kStatus[status]}): ${api.message()}`
                             : `the reference stopped (${kStatus[twinStatus]}): ${this.api.message()}`,
        };
      } else {
        const a = statePositions(module, api), b = statePositions(this.engine, this.api);
        let worst = a.length === b.length ? 0 : Infinity, at = -1;
        for (let k = 0; k < Math.min(a.length, b.length); ++k) {
          const d = Math.abs(a[k] - b[k]);
          if (d > worst) { worst = d; at = Math.floor(k / 3); }
        }
        this.worst = Math.max(this.worst, worst);
        if (worst > this.tolerance) {
          this.first = {
            frame: this.frames, time: api.time(), particle: at, distance: worst,
            text: `particle ${at} is ${formatValue(worst)} m from where the reference has it ` +
                  `(in x, y or z; the tolerance is ${formatValue(this.tolerance)} m)`,
          };
          setRunning(false);  // stay on the frame that differs
        }
      }
      this.show();
    },
    show() {
      const box = $('compare-result');
      if (!box) return;
      if (!this.on) {
        box.textContent = '';
        return;
      }
      box.className = this.first ? 'differs' : 'same';
      box.textContent = this.first
        ? `First difference at frame ${this.first.frame} (t = ${this.first.time.toFixed(4)} s): ${this.first.text}`
        : `${this.frames} frames alike (largest difference ${formatValue(this.worst)} m)`;
    },
  };

  function setupCompare() {
    const factory = typeof createClothlabReference === 'function' ? createClothlabReference : null;
    $('compare-box').style.display = factory ? '' : 'none';
    if (!factory) return;
    $('compare-tolerance').value = twin.tolerance;
    $('compare-tolerance').addEventListener('change', () => {
      const tolerance = Number($('compare-tolerance').value);
      if (tolerance >= 0) twin.tolerance = tolerance;
    });
    $('compare').addEventListener('change', () => {
      if ($('compare').checked) twin.start(factory);
      else twin.stop();
    });
  }

  // --- The mouse --------------------------------------------------------------------------
  const drag = { particle: -1 };

  function grabAt(clientX, clientY) {
    const i = view.pick(clientX, clientY);
    if (i < 0) return -1;
    if (!check(api.grab(i))) return -1;
    if (twin.on) twin.api.grab(i);
    drag.particle = i;
    if (view.controls) view.controls.enabled = false;
    return i;
  }

  function dragTo(clientX, clientY) {
    if (drag.particle < 0) return;
    const x = positions();
    const i = drag.particle;
    const target = view.pointOnPlane(clientX, clientY, [x[3 * i], x[3 * i + 1], x[3 * i + 2]]);
    if (!target) return;
    check(api.drag(i, ...target));
    if (twin.on) twin.api.drag(i, ...target);
  }

  function release() {
    if (drag.particle < 0) return;
    api.release(drag.particle);
    if (twin.on) twin.api.release(drag.particle);
    drag.particle = -1;
    if (view.controls) view.controls.enabled = true;
  }

  function setupMouse() {
    const canvas = $('canvas');
    canvas.addEventListener('pointerdown', (e) => {
      if (grabAt(e.clientX, e.clientY) >= 0) {
        e.stopImmediatePropagation();
        canvas.setPointerCapture(e.pointerId);
      }
    }, true);
    canvas.addEventListener('pointermove', (e) => dragTo(e.clientX, e.clientY));
    canvas.addEventListener('pointerup', release);
    canvas.addEventListener('pointercancel', release);
  }

  // --- The frame loop ---------------------------------------------------------------------
  let lastFrame = 0;
  function frame(now) {
    const seconds = lastFrame ? Math.min((now - lastFrame) / 1000, 0.1) : 0;
    lastFrame = now;
    if (running && seconds > 0) advance(seconds * Number($('speed').value));
    view.update();
    view.draw();
    energy.draw();
    showStats();
    requestAnimationFrame(frame);
  }

  function showStats() {
    const stepsPerSecond = stats.stepMs > 0 ? 1000 / stats.stepMs : 0;
    $('overlay').textContent =
      `t = ${api.time().toFixed(3)} s   steps ${stats.steps}\n` +
      `${stats.stepMs > 0 ? `${stats.stepMs.toFixed(3)} ms per step (${Math.round(stepsPerSecond)} steps/s)` : 'ms per step: not measured yet'}   ` +
      `${api.particles()} particles   ${view.kind}`;
  }

  // --- Start ------------------------------------------------------------------------------
  // The module steps two doubles an instruction with WebAssembly SIMD (engine/web/CMakeLists.txt):
  // a browser without it could not compile it. Asked first with a module of one function that
  // returns f64x2.splat(0), so that such a browser says what it lacks.
  const simd = new Uint8Array([0, 97, 115, 109, 1, 0, 0, 0, 1, 5, 1, 96, 0, 1, 123, 3, 2, 1, 0,
    10, 15, 1, 13, 0, 68, 0, 0, 0, 0, 0, 0, 0, 0, 253, 20, 11]);
  if (typeof WebAssembly !== 'object' || !WebAssembly.validate(simd)) {
    showMessage('This page needs WebAssembly with SIMD, which this browser lacks: open it in ' +
      'Chromium or Chrome 91, Firefox 89, Safari 16.4 or later.', 'error');
    return;
  }
  createClothlab().then((m) => {
    module = m;
    api = bind(m);
    source = sourceOf(m, api);
    $('title').textContent = lesson.title;
    $('build').textContent = lesson.kernels === 'solutions'
      ? 'the reference solutions' : 'your exercises (exercises/)';
    setupControls();
    setupDisplay();
    setupCompare();
    setupMouse();
    // The address may name the scene and a time to start from, and ask to wait there paused:
    // page.html#scene=flag.toml&t=2 (and &paused).
    const wish = new URLSearchParams(location.hash.slice(1));
    const first = lesson.scenes.find((s) => s.name.endsWith('/' + wish.get('scene'))) || lesson.scenes[0];
    $('scene').value = first.name;
    load(first.text, first.name);
    const start = Number(wish.get('t'));
    for (let t = 0; start > 0 && t < start - 1e-9 && !failed; t += 1 / 60) advance(Math.min(1 / 60, start - t));
    if (wish.has('paused')) setRunning(false);
    showStats();
    requestAnimationFrame(frame);
    // For tests and for the curious: the page's own functions.
    window.clothlabPage = {
      lesson, api, load, setParameter, advance, grabAt, dragTo, release,
      positions: () => Array.from(positions()),
      strains: () => Array.from(source.strains()),
      message: () => $('message').textContent,
      parameters: () => parameters,
      sceneText: () => sceneText,
      setRunning, view, twin,
      ready: true,
    };
    document.dispatchEvent(new Event('clothlab-ready'));
  }).catch((e) => showMessage(`the engine did not start: ${e}`, 'error'));
})();
