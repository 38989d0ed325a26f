// page_test.js: put into a copy of a live lesson page by check_pages.py, it drives the page the
// way a student would (its own functions, the ones the controls and the mouse call) and logs
// what it found to the console as one line, "CLOTHLAB-TEST " and the results as base64 JSON,
// which the driver reads from the browser's log.
'use strict';

(function () {
  const results = { checks: [], errors: window.__clothlabErrors };
  const say = (name, ok, detail) => results.checks.push({ name, ok: !!ok, detail: String(detail) });
  const finish = () => {
    const json = JSON.stringify(results);
    const bytes = new TextEncoder().encode(json);
    let binary = '';
    for (const b of bytes) binary += String.fromCharCode(b);
    console.log('CLOTHLAB-TEST ' + btoa(binary));
  };

  async function run() {
    const page = window.clothlabPage;
    const api = page.api;
    const student = page.lesson.kernels !== 'solutions';
    page.setRunning(false);
    const first = page.lesson.scenes[0];

    // A student page on stubs: the first step names the exercise to do.
    if (student) {
      page.load(first.text, first.name);
      page.advance(0.05);
      const message = page.message();
      say('a stub shows its exercise', /exercise|ex\d\d/i.test(message) && /lesson/i.test(message), message);
      // Side by side with the reference: the first frame is where the stub stops.
      // (A stub the scene's construction calls stops it at frame 0, before any step.)
      await page.twin.start(createClothlabReference);
      page.setRunning(false);
      page.advance(1 / 60);
      const stop = page.twin.first;
      say('side by side, the first difference is where the stub stops',
          stop && stop.frame <= 1 && /your code stopped/.test(stop.text) && /ex\d\d/.test(stop.text),
          JSON.stringify(stop));
      if (stop && stop.frame === 1) {
        for (let k = 0; k < 600 && page.twin.api.steps() === 0; ++k) page.advance(1 / 60);
        say('side by side, the reference runs on', page.twin.api.time() > 0 && page.twin.api.steps() > 0,
            `t = ${page.twin.api.time()}`);
      }
      return;
    }

    const calm = [];  // the scenes that run without the guard stopping them
    const blowups = [];  // the scenes that blow up on purpose
    for (const scene of page.lesson.scenes) {
      // Time advances.
      if (!page.load(scene.text, scene.name)) {
        say(`${scene.name} loads`, false, page.message());
        continue;
      }
      page.setRunning(false);
      // Every effect the scene names has its sliders, offered by the engine's scene reader:
      // each table but those that set up bodies, the step, the output and the engine. (The page
      // once kept a list of its own, which named [strain_limiting] for lesson 09's
      // [strain_limit].)
      const headings = Array.from(document.querySelectorAll('#sliders .slider-table'), (n) => n.textContent);
      const effects = Array.from(scene.text.matchAll(/^\s*\[\[?\s*([A-Za-z_]+)\s*\]/gm), (m) => m[1])
        .filter((t) => !/^(guard|particle|rope|cloth|solid|integrator|output|engine|title)$/.test(t));
      const bare = effects.filter((t) => !headings.some((h) => h === `[${t}]` || h.startsWith(`[[${t}]]`)));
      say(`${scene.name}: each effect of the scene has its sliders`, bare.length === 0,
          `no slider under ${bare.join(', ')}; headings: ${headings.join(' ')}`);
      const method = /^\s*method\s*=\s*"([^"]+)"/m.exec(scene.text);
      const shown = document.getElementById('integrator').value;
      say(`${scene.name}: the integrator menu shows the scene's method`,
          shown === (method ? method[1] : 'symplectic-euler'), shown);
      // A scene with a ground not far below the cloth is framed down to the ground, so that
      // what falls on it stays in view: the camera aims halfway between the ground and the top.
      const ground = JSON.parse(api.colliders()).ground;
      const box = ClothlabRender.bounds(page.positions());
      if (ground !== null && ground < box.lo[1] && box.lo[1] - ground <= 3 * box.size && page.view.controls) {
        const aim = page.view.controls.target.y, halfway = (ground + box.hi[1]) / 2;
        say(`${scene.name}: the view frames the cloth and the ground below it`,
            Math.abs(aim - halfway) < 1e-9 * Math.max(1, box.size), `aims at y = ${aim}, not ${halfway}`);
      }
      // Frames of 1/60 s for a sixth of a second, or three steps of a scene's larger dt.
      const t0 = api.time(), span = Math.max(1 / 6, 3 * api.dt());
      let ok = true;
      for (let t = 0; t < span - 1e-9 && ok; t += 1 / 60) ok = page.advance(1 / 60);
      if (ok) {
        say(`${scene.name}: simulated time advances`, api.time() >= t0 + span - api.dt() - 1e-9,
            `t = ${api.time()} after ${span} s of frames (dt = ${api.dt()})`);
        // The module's fast path (built with SIMD) and the lecture's readable path give the
        // same state, bit for bit, as they do natively (tests/fast/). Implicit Euler's engine
        // room solves the same system by another order of the same sums, to the scene's
        // tolerance (tests/fast/implicit.cpp derives the bound): its scenes are run again both
        // ways with the solves taken to rounding, and must agree to a micrometre.
        const implicit = method !== null && method[1] === 'implicit-euler';
        const exact = (text) => text.replace(/^\s*(tolerance|max_iterations)\s*=.*$/gm, '')
          .replace(/^\s*\[integrator\]\s*$/m, '[integrator]\ntolerance = 1e-12\nmax_iterations = 20000');
        const run = (text, steps) => {
          page.load(text, scene.name);
          page.setRunning(false);
          for (let k = 0; k < 600 && api.steps() < steps && ok; ++k) ok = page.advance(1 / 60);
          return page.positions();
        };
        const steps = api.steps();
        const fast = implicit ? run(exact(scene.text), steps) : page.positions();
        const readable = run(`${implicit ? exact(scene.text) : scene.text}\n[engine]\nfast_path = false\n`, steps);
        const allowed = implicit ? 1e-6 : 0;
        const differ = readable.findIndex((value, k) => !(Math.abs(value - fast[k]) <= allowed));
        calm.push(scene);
        say(`${scene.name}: the fast path and the readable path agree ${implicit ?
              'to a micrometre (implicit Euler, solves to rounding)' : 'bit for bit'}`,
            ok && api.steps() === steps && readable.length === fast.length && differ < 0,
            `${api.steps()} steps against ${steps}; ${differ < 0 ? 'no difference' :
              `coordinate ${differ}: ${readable[differ]} against ${fast[differ]}`}; ${page.message()}`);
      } else {
        // A scene that blows up on purpose (lesson 08) stops with the guard's message.
        say(`${scene.name}: the run stops with the guard's message`,
            /blew up|guard/.test(page.message()) && api.time() > t0, page.message());
        blowups.push(scene);
      }
    }

    // Single precision in the page ([engine] precision = "float", the engine room's float room):
    // a calm scene float covers steps in float, near its double run; a scene float does not
    // cover is refused with what float covers. And one of them, at least, is not on its double
    // run (a page that stepped in double whatever the scene said would give the same numbers;
    // a single particle's drop onto the ground may, all its numbers floats).
    const inFloat = (text) => `${text}\n[engine]\nprecision = "float"\n`;
    let covered = 0, apart = null, single = null;
    for (const scene of calm) {
      if (/^\s*\[engine\]/m.test(scene.text)) continue;  // a scene that sets its engine itself
      if (!page.load(inFloat(scene.text), scene.name)) {
        say(`${scene.name} in float: refused, saying what float covers`,
            /float covers .*symplectic-euler/.test(page.message()), page.message());
        continue;
      }
      ++covered;
      single = single || scene;
      page.setRunning(false);
      let ok = true;
      for (let k = 0; k < 10 && ok; ++k) ok = page.advance(1 / 60);
      const steps = api.steps();
      const inSingle = page.positions();
      page.load(scene.text, scene.name);
      page.setRunning(false);
      for (let k = 0; k < 600 && api.steps() < steps && ok; ++k) ok = page.advance(1 / 60);
      const inDouble = page.positions();
      let gap = 0, size = 1;
      inDouble.forEach((x, k) => {
        gap = Math.max(gap, Math.abs(x - inSingle[k]));
        size = Math.max(size, Math.abs(x));
      });
      say(`${scene.name} in float: steps in single precision, near the double run`,
          ok && steps > 0 && api.steps() === steps && inSingle.length === inDouble.length &&
            gap <= 1e-4 * size,
          `${steps} steps, largest difference ${gap} m (coordinates up to ${size} m); ${page.message()}`);
      if (gap > 0) {
        apart = `${scene.name}: ${gap} m after ${steps} steps`;
        break;
      }
    }
    if (covered > 0) say('a scene in float is not its double run', apart !== null, apart);

    // The engine room tests the state for the guard as it copies it, before a step moves
    // anything: a particle put far out between two steps (dragged to 1e9 m, past the guard's
    // bound of 1e6 m) stops the next step with the guard's message for a state that was bad
    // before the step, in double and in float (the module copies four particles at a time there).
    const farOut = (text, name, what) => {
      if (!page.load(text, name)) return;
      page.setRunning(false);
      const i = Math.min(5, api.particles() - 1);
      const moved = api.grab(i) === 0 && api.drag(i, 1e9, 0, 0) === 0;
      const ok = moved && page.advance(Math.max(1 / 60, api.dt()));  // a step at least
      say(`${name} ${what}: a particle dragged to 1e9 m stops the next step before it moves`,
          moved && !ok && /before step/.test(page.message()), page.message());
    };
    if (calm.length) farOut(calm[0].text, calm[0].name, 'in double');
    if (single) farOut(inFloat(single.text), single.name, 'in float');

    // And it tests the new state as it moves it: a scene that blows up in a step stops with the
    // guard's message for that step, not for the state before the next one, in float too (the
    // module writes the float room's state back four particles at a time, testing it as it goes;
    // a cloth of 20 x 20 leaves no particle over for its one-at-a-time loop, which would catch
    // the blow-up on its own).
    const blowup = blowups.find((scene) => !/^\s*\[engine\]/m.test(scene.text) &&
                                           /^\s*\[cloth\]/m.test(scene.text));
    const square = blowup && blowup.text.replace(/^(\s*rows\s*=\s*)\d+/m, '$120')
      .replace(/^(\s*cols\s*=\s*)\d+/m, '$120');
    if (blowup && page.load(inFloat(square), blowup.name)) {
      page.setRunning(false);
      let ok = true;
      for (let k = 0; k < 600 && ok; ++k) ok = page.advance(1 / 60);
      say(`${blowup.name} in float, 20 x 20: the step that blows up stops with the guard's message`,
          api.particles() === 400 && !ok && /blew up at step/.test(page.message()), page.message());
    }

    // A start past a float's range, which a widened [guard] lets through: the page draws its
    // positions as 32-bit floats, so it refuses the scene at the key that set it, as clothlab run
    // refuses it for a page; a start just within the range loads.
    const farScene = (y) => `[guard]\nmax_position = 1e300\n[[particle]]\nposition = [0, ${y}, 0]\n` +
      'mass = 1\n[integrator]\ndt = 0.01\nduration = 0.05\n';
    say('a start past a float\'s range is refused at its key, saying that the page draws in floats',
        !page.load(farScene('1e39'), 'far.toml') &&
          /far\.toml:4:12: .*beyond what a 32-bit float holds.*the page draws positions as 32-bit floats/
            .test(page.message()), page.message());
    say('a start within a float\'s range loads', page.load(farScene('1e38'), 'near.toml'),
        page.message());

    // A slider changes the motion: the same scene, run twice for 0.6 s, once with the first
    // slider's number five times larger (or 1 if it is 0). (Long enough for lesson 09's jelly
    // cube, whose springs first bend when it lands, after 0.32 s of free fall.)
    page.load(first.text, first.name);
    page.setRunning(false);
    const sliders = Array.from(document.querySelectorAll('#sliders input'));
    if (sliders.length) {
      for (let k = 0; k < 36; ++k) page.advance(1 / 60);
      const plain = page.positions();
      page.load(first.text, first.name);
      page.setRunning(false);
      const name = sliders[0].dataset.name;
      const p = page.parameters().find((q) => q.name === name);
      const value = p.value === 0 ? 1 : p.value * 5;
      const changed = page.setParameter(name, value);
      for (let k = 0; k < 36; ++k) page.advance(1 / 60);
      const other = page.positions();
      let diff = 0;
      for (let k = 0; k < plain.length; ++k) diff = Math.max(diff, Math.abs(plain[k] - other[k]));
      say(`the slider ${name} changes the motion`, changed && diff > 1e-6,
          `max difference ${diff} m; ${page.message()}`);
      say(`the slider ${name} is in the scene's text`, page.sceneText().includes(String(value)), page.sceneText());
      // Each slider is told apart from the others under its table's heading: no two labels in
      // one table alike, a vector's elements named by axis, the full name in its tooltip.
      const labels = new Set();
      let table = '';
      const clashes = [];
      for (const node of document.querySelectorAll('#sliders > *')) {
        if (node.className === 'slider-table') {
          table = node.textContent;
          continue;
        }
        const label = node.querySelector('span');
        const full = node.querySelector('input').dataset.name;
        const key = `${table} ${label.textContent}`;
        if (labels.has(key) || label.title !== full || !table.includes(full.split('.')[0])) clashes.push(key);
        labels.add(key);
        const axis = /\[(\d)\]$/.exec(full);
        const vector = page.parameters().filter((q) => q.name.startsWith(full.replace(/\[\d\]$/, '['))).length;
        if (axis && vector === 3 && !label.textContent.endsWith(` ${'xyz'[Number(axis[1])]}`)) clashes.push(key);
      }
      say('each slider has its own label under its table, a vector\'s by axis', clashes.length === 0,
          clashes.join(', '));
    } else {
      say('the first scene has sliders', false, 'none');
    }

    // A drag: hold a free particle and pull it; it follows the mouse.
    page.load(first.text, first.name);
    page.setRunning(false);
    page.view.draw();
    let free = -1;
    for (let i = 0; i < api.particles(); ++i) if (!api.isPinned(i)) { free = i; break; }
    if (free >= 0) {
      const [sx, sy] = page.view.screenOf(free);
      const grabbed = page.grabAt(sx, sy);
      const before = page.positions().slice(3 * grabbed, 3 * grabbed + 3);
      page.dragTo(sx + 60, sy - 60);
      const span = Math.max(0.1, 3 * api.dt());
      for (let t = 0; t < span - 1e-9; t += 1 / 60) page.advance(1 / 60);
      const after = page.positions().slice(3 * grabbed, 3 * grabbed + 3);
      const moved = Math.hypot(after[0] - before[0], after[1] - before[1], after[2] - before[2]);
      say('a drag moves the grabbed particle', grabbed >= 0 && moved > 1e-4 && api.isPinned(grabbed),
          `particle ${grabbed} moved ${moved} m`);
      page.release();
      say('a released particle is free again', !api.isPinned(grabbed), grabbed);
    }

    // Side by side: the same build twice never differs; a particle moved in one of them alone
    // is the first difference, at the frame it moved.
    page.load(first.text, first.name);
    await page.twin.start(createClothlab);
    page.setRunning(false);
    // Each half-width pane frames its cloth: the pins (or, with none, every particle) of each
    // are drawn inside their own pane, not cut off at its sides.
    page.view.draw();
    const whole = document.getElementById('canvas').getBoundingClientRect();
    const pins = [];
    for (let i = 0; i < api.particles(); ++i) if (api.isPinned(i)) pins.push(i);
    const shown = pins.length ? pins : Array.from({ length: api.particles() }, (_, i) => i);
    const outside = [];
    for (const pane of [0, 1]) {
      const left = whole.left + pane * whole.width / 2, right = left + whole.width / 2;
      for (const i of shown) {
        const [sx, sy] = page.view.screenOf(i, pane);
        if (!(sx >= left && sx <= right && sy >= whole.top && sy <= whole.bottom)) outside.push([pane, i, Math.round(sx), Math.round(sy)]);
      }
    }
    say(`side by side, each pane frames its cloth (${pins.length ? 'pins' : 'particles'} inside their pane)`,
        shown.length > 0 && outside.length === 0,
        `${page.view.kind} canvas ${Math.round(whole.width)} x ${Math.round(whole.height)}; outside [pane, particle, x, y]: ${JSON.stringify(outside.slice(0, 6))}`);
    for (let k = 0; k < 6; ++k) page.advance(1 / 60);
    say('side by side, the same code runs alike', !page.twin.first && page.twin.worst === 0 && page.twin.frames === 6,
        `${JSON.stringify(page.twin.first)} worst ${page.twin.worst} after ${page.twin.frames} frames`);
    // Particle i pulled dx along x in this page's engine alone, over frames of 1/60 s until a
    // step has taken the pull (a frame shorter than dt may take none).
    const pull = (i, dx) => {
      const x = page.positions();
      api.grab(i);
      api.drag(i, x[3 * i] + dx, x[3 * i + 1], x[3 * i + 2]);
      const steps = api.steps();
      for (let k = 0; k < 100 && api.steps() === steps; ++k) page.advance(1 / 60);
      api.release(i);
    };
    if (free >= 0) {
      pull(free, 0.01);
      const difference = page.twin.first || {};
      say('side by side, a particle moved in one build is the first difference, at its frame',
          difference.frame === page.twin.frames && difference.frame > 6 && difference.distance > 1e-3 &&
          difference.particle >= 0 && difference.particle < api.particles(),
          `${JSON.stringify(difference)} after ${page.twin.frames} frames`);
    }
    page.twin.stop();

    // Colour by strain: the engine's strain at each particle, and drawing with it.
    page.load(first.text, first.name);
    page.setRunning(false);
    // A particle pulled 5 cm away from its neighbours stretches their springs.
    if (free >= 0) pull(free, 0.05);
    page.view.settings.strain = true;
    page.view.settings.springs = true;
    page.view.update();
    page.view.draw();
    const strains = page.strains();
    const largest = Math.max(...strains.map(Math.abs));
    say('colour by strain: the strain at each particle, from the engine', strains.length === api.particles() &&
        strains.every(Number.isFinite) && (api.springCount() === 0 || largest > 0), `largest |strain| ${largest}`);
    page.view.settings.strain = false;
    page.view.settings.springs = false;

    // A torn cloth stays torn when a slider reads its scene again (lesson 06).
    for (const scene of page.lesson.scenes) {
      if (!/^\s*\[tearing\]/m.test(scene.text)) continue;
      page.load(scene.text, scene.name);
      page.setRunning(false);
      const before = api.springCount();
      for (let k = 0; k < 600 && api.springCount() === before && !page.message(); ++k) page.advance(1 / 60);
      const torn = api.springCount(), triangles = api.triangleCount();
      if (torn === before) continue;
      const slider = page.parameters().find((q) => /^(springs|damping|gravity|aerodynamics)\./.test(q.name) && !q.integer);
      page.setParameter(slider.name, slider.value * 1.01);
      say(`${scene.name}: a slider keeps the tears (${before - torn} springs torn)`,
          api.springCount() === torn && api.triangleCount() === triangles,
          `springs ${before} -> ${torn} -> ${api.springCount()}, triangles ${triangles} -> ${api.triangleCount()}`);
    }

    // The engine's colliders are drawn: a [[plane]] scene has its plane.
    for (const scene of page.lesson.scenes) {
      if (!/^\s*\[\[plane\]\]/m.test(scene.text)) continue;
      page.load(scene.text, scene.name);
      const colliders = JSON.parse(api.colliders());
      say(`${scene.name}: the engine names its planes for drawing`, colliders.planes.length > 0, JSON.stringify(colliders));
    }

    // An edited scene with an error shows FILE:LINE:COL.
    const lines = first.text.split('\n').length;
    page.load(first.text + (first.text.endsWith('\n') ? '' : '\n') + 'mistake = 1\n', first.name);
    const expected = `${first.name}:${lines + (first.text.endsWith('\n') ? 0 : 1)}:1:`;
    say('an error in an edited scene shows its line and column', page.message().includes(expected),
        `${page.message()} (expected ${expected})`);
  }

  async function start() {
    try {
      await run();
    } catch (e) {
      say('the test ran', false, `${e}\n${e.stack}`);
    }
    finish();
  }
  if (window.clothlabPage && window.clothlabPage.ready) start();
  else document.addEventListener('clothlab-ready', start);
})();
