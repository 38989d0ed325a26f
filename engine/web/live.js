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
      triangleCount: f('clothlab_triangle_count', 'number', []),
      triangles: f('clothlab_triangles', 'number', []),
      springCount: f('clothlab_spring_count', 'number', []),
      springs: f('clothlab_springs', 'number', []),
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

  function positions() {
    const n = api.particles();
    return new Float64Array(module.HEAPF64.buffer, api.positions(), 3 * n);
  }

  function indices(pointer, count) {
    return new Int32Array(module.HEAP32.buffer, pointer, count).slice();
  }

  // --- Loading a scene --------------------------------------------------------------------
  function load(text, name) {
    sceneName = name;
    failed = false;
    showMessage('', '');
    const status = api.load(text, name);
    $('editor').value = text;
    if (!check(status)) return false;
    sceneText = text;
    loadedText = text;
    parameters = JSON.parse(api.parameters());
    stats.steps = 0;
    energy.clear();
    buildSliders();
    readIntegrator();
    view.rebuild(true);
    setRunning(true);
    return true;
  }

  // Changes the number at `path` to `value` and goes on with the motion.
  function setParameter(path, value) {
    const text = editText(sceneText, path, value);
    if (text === null) return false;
    const status = api.reload(text, sceneName);
    if (status !== 0) {
      // The value is refused (out of range, ...): say why, keep the scene that ran.
      showMessage(`${path} = ${value}: ${api.message()}`, 'error');
      api.reload(sceneText, sceneName);
      return false;
    }
    showMessage('', '');
    failed = false;
    sceneText = text;
    $('editor').value = text;
    parameters = JSON.parse(api.parameters());
    view.rebuild(false);
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

  // The numbers a slider is offered for: the physics, not the geometry or the output.
  const kSliderTables = /^(springs|bending|aerodynamics|drag|damping|gravity|gravitation|ground|sphere|plane|tearing|plasticity|strain_limiting|buoyancy|self_collision)\./;

  function formatValue(v) {
    if (v === 0) return '0';
    const a = Math.abs(v);
    return a >= 1e4 || a < 1e-3 ? v.toExponential(3) : String(Number(v.toPrecision(4)));
  }

  // A slider over [value / 10, value * 10] on a log scale for a positive number; linear over
  // a symmetric range for one that may be negative or is 0.
  function sliderScale(p) {
    const v = p.value;
    if (v > 0 && !p.name.includes('[')) {
      const lo = Math.log(v / 10), hi = Math.log(v * 10);
      return { to: (s) => Math.exp(lo + (hi - lo) * s), from: (x) => (Math.log(x) - lo) / (hi - lo) };
    }
    const span = Math.max(Math.abs(v) * 3, 1);
    return { to: (s) => -span + 2 * span * s, from: (x) => (x + span) / (2 * span) };
  }

  function buildSliders() {
    const box = $('sliders');
    box.textContent = '';
    for (const p of parameters) {
      if (!kSliderTables.test(p.name) || p.integer) continue;
      const row = document.createElement('label');
      row.className = 'slider';
      const name = document.createElement('span');
      name.textContent = p.name;
      name.title = p.name;
      const input = document.createElement('input');
      input.type = 'range';
      input.min = 0;
      input.max = 1000;
      input.dataset.name = p.name;
      const out = document.createElement('output');
      const scale = sliderScale(p);
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
    const method = /^\s*method\s*=\s*"([^"]*)"/m.exec(section(sceneText, 'integrator'));
    $('integrator').value = method ? method[1] : 'symplectic-euler';
  }

  // The text of [table] in a scene, up to the next table.
  function section(text, table) {
    const header = new RegExp(`^[ \\t]*\\[${table}\\][^\\n]*$`, 'm').exec(text);
    if (!header) return '';
    const rest = text.slice(header.index + header[0].length);
    const next = rest.search(/^[ \t]*\[/m);
    return next < 0 ? rest : rest.slice(0, next);
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
    draw() {
      const c = $('energy');
      const g = c.getContext('2d');
      g.clearRect(0, 0, c.width, c.height);
      const n = this.t.length;
      if (n < 2) return;
      const total = this.k.map((k, i) => k + this.u[i]);
      const all = this.k.concat(this.u, total);
      let lo = Math.min(...all), hi = Math.max(...all);
      if (hi - lo < 1e-12) { hi += 1; lo -= 1; }
      const x = (i) => 4 + (c.width - 8) * (this.t[i] - this.t[0]) / Math.max(this.t[n - 1] - this.t[0], 1e-12);
      const y = (v) => c.height - 4 - (c.height - 8) * (v - lo) / (hi - lo);
      const line = (values, colour) => {
        g.strokeStyle = colour;
        g.beginPath();
        values.forEach((v, i) => (i ? g.lineTo(x(i), y(v)) : g.moveTo(x(i), y(v))));
        g.stroke();
      };
      line(this.k, '#c0392b');
      line(this.u, '#2c6e9e');
      line(total, '#222');
      g.fillStyle = '#555';
      g.font = '10px monospace';
      g.fillText(`${formatValue(hi)} J`, 6, 12);
      g.fillText(`${formatValue(lo)} J`, 6, c.height - 6);
    },
  };

  // --- Drawing ----------------------------------------------------------------------------
  const view = makeView();

  function makeView() {
    const canvas = $('canvas');
    let renderer = null;
    try {
      renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
    } catch (e) {
      renderer = null;
    }
    if (!renderer || !renderer.getContext()) return makeCanvasView(canvas);
    renderer.shadowMap.enabled = true;
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0xdfe6ec);
    const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
    const controls = new THREE.OrbitControls(camera, canvas);
    controls.enableDamping = true;
    scene.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 0.55));
    const sun = new THREE.DirectionalLight(0xffffff, 0.75);
    sun.castShadow = true;
    sun.shadow.mapSize.set(1024, 1024);
    scene.add(sun, sun.target);

    let geometry = null, front = null, back = null, lines = null, points = null, grid = null, floor = null;
    let pinMarks = null, ball = null;
    // Front and back of the cloth in different colours, both lit (two-sided lighting).
    const frontMaterial = new THREE.MeshPhongMaterial({ color: 0xc8553d, side: THREE.FrontSide, shininess: 20 });
    const backMaterial = new THREE.MeshPhongMaterial({ color: 0x3d7ec8, side: THREE.BackSide, shininess: 20 });

    function clear() {
      for (const o of [front, back, lines, points, grid, floor, pinMarks, ball]) if (o) scene.remove(o);
      front = back = lines = points = grid = floor = pinMarks = ball = null;
    }

    function rebuild(frame) {
      const n = api.particles();
      const x = positions();
      const keepCamera = !frame;
      clear();
      geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
      const tris = api.triangleCount();
      if (tris > 0) {
        geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(indices(api.triangles(), 3 * tris)), 1));
        front = new THREE.Mesh(geometry, frontMaterial);
        back = new THREE.Mesh(geometry, backMaterial);
        front.castShadow = back.castShadow = true;
        scene.add(front, back);
      } else {
        const springs = api.springCount();
        if (springs > 0) {
          const lineGeometry = new THREE.BufferGeometry();
          lineGeometry.setAttribute('position', geometry.getAttribute('position'));
          lineGeometry.setIndex(new THREE.BufferAttribute(new Uint32Array(indices(api.springs(), 2 * springs)), 1));
          lines = new THREE.LineSegments(lineGeometry, new THREE.LineBasicMaterial({ color: 0x333333 }));
          scene.add(lines);
        }
        points = new THREE.Points(geometry, new THREE.PointsMaterial({ color: 0xc8553d, size: 6, sizeAttenuation: false }));
        scene.add(points);
      }
      // Pins, and the particle the mouse holds, as dots.
      pinMarks = new THREE.Points(new THREE.BufferGeometry(), new THREE.PointsMaterial({ color: 0x111111, size: 7, sizeAttenuation: false }));
      scene.add(pinMarks);
      // The ground: from [ground] y, else below the scene.
      const box = bounds(x);
      const groundY = groundHeight(box);
      const size = Math.max(box.size, 1e-3);
      grid = new THREE.GridHelper(size * 4, 20, 0x888888, 0xbbbbbb);
      grid.position.set(box.centre[0], groundY, box.centre[2]);
      floor = new THREE.Mesh(new THREE.PlaneGeometry(size * 4, size * 4), new THREE.ShadowMaterial({ opacity: 0.25 }));
      floor.rotation.x = -Math.PI / 2;
      floor.position.set(box.centre[0], groundY + size * 1e-3, box.centre[2]);
      floor.receiveShadow = true;
      scene.add(grid, floor);
      // A [sphere] collider, a little smaller than it is so that the cloth on it shows.
      const value = (name) => (parameters.find((q) => q.name === name) || {}).value;
      const radius = value('sphere.radius');
      if (radius > 0) {
        ball = new THREE.Mesh(new THREE.SphereGeometry(0.98 * radius, 48, 24),
                              new THREE.MeshPhongMaterial({ color: 0x9aa3ab }));
        ball.position.set(value('sphere.centre[0]') || 0, value('sphere.centre[1]') || 0,
                          value('sphere.centre[2]') || 0);
        ball.castShadow = ball.receiveShadow = true;
        scene.add(ball);
      }
      sun.position.set(box.centre[0] + size, box.centre[1] + 3 * size, box.centre[2] + 2 * size);
      sun.target.position.set(box.centre[0], groundY, box.centre[2]);
      const cam = sun.shadow.camera;
      cam.left = cam.bottom = -2 * size;
      cam.right = cam.top = 2 * size;
      cam.near = 0.01 * size;
      cam.far = 10 * size;
      cam.updateProjectionMatrix();
      if (!keepCamera) {
        controls.target.set(box.centre[0], box.centre[1], box.centre[2]);
        camera.position.set(box.centre[0] + 0.6 * size, box.centre[1] + 0.5 * size, box.centre[2] + 2.2 * size);
        camera.near = size * 1e-3;
        camera.far = size * 1e3;
        camera.updateProjectionMatrix();
      }
      update();
    }

    function update() {
      if (!geometry) return;
      const x = positions();
      const attribute = geometry.getAttribute('position');
      attribute.array.set(x);
      attribute.needsUpdate = true;
      if (front) geometry.computeVertexNormals();
      geometry.computeBoundingSphere();
      const pins = [];
      const n = api.particles();
      for (let i = 0; i < n; ++i) if (api.isPinned(i)) pins.push(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
      pinMarks.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pins), 3));
    }

    function draw() {
      const w = canvas.clientWidth, h = canvas.clientHeight;
      if (canvas.width !== w || canvas.height !== h) {
        renderer.setSize(w, h, false);
        camera.aspect = w / Math.max(h, 1);
        camera.updateProjectionMatrix();
      }
      controls.update();
      renderer.render(scene, camera);
    }

    // The particle nearest the ray under the mouse (within a few pixels), or -1.
    function pick(clientX, clientY) {
      const rect = canvas.getBoundingClientRect();
      const x = positions();
      let best = -1, bestDistance = 12;  // [px]
      const p = new THREE.Vector3();
      for (let i = 0; i < api.particles(); ++i) {
        p.set(x[3 * i], x[3 * i + 1], x[3 * i + 2]).project(camera);
        const sx = rect.left + (p.x + 1) / 2 * rect.width, sy = rect.top + (1 - p.y) / 2 * rect.height;
        const d = Math.hypot(sx - clientX, sy - clientY);
        if (d < bestDistance) { bestDistance = d; best = i; }
      }
      return best;
    }

    // Where the mouse points on the plane through `point` facing the camera.
    function pointOnPlane(clientX, clientY, point) {
      const rect = canvas.getBoundingClientRect();
      const ndc = new THREE.Vector2((clientX - rect.left) / rect.width * 2 - 1, -(clientY - rect.top) / rect.height * 2 + 1);
      const ray = new THREE.Raycaster();
      ray.setFromCamera(ndc, camera);
      const normal = new THREE.Vector3();
      camera.getWorldDirection(normal);
      const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, new THREE.Vector3(...point));
      const hit = new THREE.Vector3();
      return ray.ray.intersectPlane(plane, hit) ? [hit.x, hit.y, hit.z] : null;
    }

    // Where particle i is on the screen [px].
    function screenOf(i) {
      const x = positions();
      const p = new THREE.Vector3(x[3 * i], x[3 * i + 1], x[3 * i + 2]).project(camera);
      const rect = canvas.getBoundingClientRect();
      return [rect.left + (p.x + 1) / 2 * rect.width, rect.top + (1 - p.y) / 2 * rect.height];
    }

    return { kind: 'webgl', rebuild, update, draw, pick, pointOnPlane, screenOf, controls };
  }

  // Without WebGL: the particles and springs drawn flat on a 2D canvas, seen from the front.
  function makeCanvasView(canvas) {
    const g = canvas.getContext('2d');
    let box = null;
    const screen = (x, i) => {
      const w = canvas.width, h = canvas.height, s = 0.8 * Math.min(w, h) / Math.max(box.size, 1e-9);
      return [w / 2 + s * (x[3 * i] - box.centre[0]), h / 2 - s * (x[3 * i + 1] - box.centre[1])];
    };
    return {
      kind: '2d',
      rebuild() { box = bounds(positions()); },
      update() {},
      draw() {
        canvas.width = canvas.clientWidth;
        canvas.height = canvas.clientHeight;
        const x = positions();
        g.clearRect(0, 0, canvas.width, canvas.height);
        const tris = indices(api.triangles(), 3 * api.triangleCount());
        g.strokeStyle = '#c8553d';
        g.beginPath();
        for (let k = 0; k < tris.length; k += 3) {
          const a = screen(x, tris[k]), b = screen(x, tris[k + 1]), c = screen(x, tris[k + 2]);
          g.moveTo(...a); g.lineTo(...b); g.lineTo(...c); g.closePath();
        }
        g.stroke();
        g.fillStyle = '#222';
        for (let i = 0; i < api.particles(); ++i) g.fillRect(...screen(x, i).map((v) => v - 1.5), 3, 3);
      },
      pick(clientX, clientY) {
        const x = positions();
        let best = -1, bestDistance = 12;
        for (let i = 0; i < api.particles(); ++i) {
          const [sx, sy] = this.screenOf(i, x);
          const d = Math.hypot(sx - clientX, sy - clientY);
          if (d < bestDistance) { bestDistance = d; best = i; }
        }
        return best;
      },
      screenOf(i, x = positions()) {
        const rect = canvas.getBoundingClientRect();
        const [sx, sy] = screen(x, i);
        return [rect.left + sx, rect.top + sy];
      },
      pointOnPlane(clientX, clientY, point) {
        const rect = canvas.getBoundingClientRect();
        const s = 0.8 * Math.min(canvas.width, canvas.height) / Math.max(box.size, 1e-9);
        return [box.centre[0] + (clientX - rect.left - canvas.width / 2) / s,
                box.centre[1] - (clientY - rect.top - canvas.height / 2) / s, point[2]];
      },
      controls: null,
    };
  }

  function bounds(x) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < x.length; i += 3) {
      for (let a = 0; a < 3; ++a) {
        lo[a] = Math.min(lo[a], x[i + a]);
        hi[a] = Math.max(hi[a], x[i + a]);
      }
    }
    if (x.length === 0) return { centre: [0, 0, 0], size: 1, lo: [0, 0, 0], hi: [0, 0, 0] };
    const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 0.1);
    return { centre: lo.map((l, a) => (l + hi[a]) / 2), size, lo, hi };
  }

  function groundHeight(box) {
    const y = parameters.find((p) => p.name === 'ground.y');
    if (y) return y.value;
    if (/^\s*\[ground\]/m.test(sceneText)) return 0;
    return box.lo[1] - 0.5 * box.size;
  }

  // --- The mouse --------------------------------------------------------------------------
  const drag = { particle: -1 };

  function grabAt(clientX, clientY) {
    const i = view.pick(clientX, clientY);
    if (i < 0) return -1;
    if (!check(api.grab(i))) return -1;
    drag.particle = i;
    if (view.controls) view.controls.enabled = false;
    return i;
  }

  function dragTo(clientX, clientY) {
    if (drag.particle < 0) return;
    const x = positions();
    const i = drag.particle;
    const target = view.pointOnPlane(clientX, clientY, [x[3 * i], x[3 * i + 1], x[3 * i + 2]]);
    if (target) check(api.drag(i, ...target));
  }

  function release() {
    if (drag.particle < 0) return;
    api.release(drag.particle);
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
    const stepsPerSecond = stats.stepMs > 0 ? 1000 / stats.stepMs : 0;
    $('overlay').textContent =
      `t = ${api.time().toFixed(3)} s   steps ${stats.steps}\n` +
      `${stats.stepMs > 0 ? `${stats.stepMs.toFixed(3)} ms per step (${Math.round(stepsPerSecond)} steps/s)` : 'ms per step: not measured yet'}   ` +
      `${api.particles()} particles   ${view.kind}`;
    requestAnimationFrame(frame);
  }

  // --- Start ------------------------------------------------------------------------------
  createClothlab().then((m) => {
    module = m;
    api = bind(m);
    $('title').textContent = lesson.title;
    $('build').textContent = lesson.kernels === 'solutions'
      ? 'the reference solutions' : 'your exercises (exercises/)';
    setupControls();
    setupMouse();
    // The address may name the scene and a time to start from: page.html#scene=flag.toml&t=2.
    const wish = new URLSearchParams(location.hash.slice(1));
    const first = lesson.scenes.find((s) => s.name.endsWith('/' + wish.get('scene'))) || lesson.scenes[0];
    $('scene').value = first.name;
    load(first.text, first.name);
    const start = Number(wish.get('t'));
    for (let t = 0; start > 0 && t < start - 1e-9 && !failed; t += 1 / 60) advance(Math.min(1 / 60, start - t));
    requestAnimationFrame(frame);
    // For tests and for the curious: the page's own functions.
    window.clothlabPage = {
      lesson, api, load, setParameter, advance, grabAt, dragTo, release,
      positions: () => Array.from(positions()),
      message: () => $('message').textContent,
      parameters: () => parameters,
      sceneText: () => sceneText,
      setRunning, view,
      ready: true,
    };
    document.dispatchEvent(new Event('clothlab-ready'));
  }).catch((e) => showMessage(`the engine did not start: ${e}`, 'error'));
})();
