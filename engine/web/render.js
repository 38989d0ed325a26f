// render.js: draws one cloth, or two side by side, with three.js (WebGL), or flat on a 2D
// canvas where WebGL is missing. The live pages (live.js) give it their engines as *sources*:
//
//   { count(), positions() (3 numbers a particle), triangles(), springs() (index arrays),
//     isPinned(i), strains() (one number a particle: l / l0 - 1), colliders() }
//
// where colliders() is { ground: height or null, planes: [{point, normal}],
// spheres: [{centre, radius}] } as the engine has them. A source may also give bounds() (the box
// the camera frames, else the first positions') and trails() (the positions so far, frame by
// frame, for drawing each particle's path; the recorded-run viewer, engine/io/viewer.html). With two
// sources the canvas is split in two panes under one camera, framed for a pane's width: the
// left pane shows the first source, the right the second.
'use strict';

const ClothlabRender = (function () {
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

  // The box the camera frames when a source gives none: the first positions and, where the
  // scene has a ground not far below them (within three times their size), the ground too, so
  // that what falls on it stays in view (lesson 09's jelly cube, dropped from 0.5 m).
  function framed(source) {
    const box = bounds(source.positions());
    const ground = source.colliders().ground;
    if (ground === null || ground === undefined || !(ground < box.lo[1]) || box.lo[1] - ground > 3 * box.size) return box;
    const lo = [box.lo[0], ground, box.lo[2]];
    const size = Math.max(box.size, box.hi[1] - ground);
    return { centre: lo.map((l, a) => (l + box.hi[a]) / 2), size, lo, hi: box.hi };
  }

  // Strain to colour: unstrained is pale, stretched red, squeezed blue, full at +-scale.
  function strainColour(e, scale, out, at) {
    const s = Math.max(-1, Math.min(1, e / scale));
    const pale = [0.93, 0.91, 0.86], red = [0.80, 0.10, 0.08], blue = [0.10, 0.30, 0.85];
    const to = s >= 0 ? red : blue, w = Math.abs(s);
    for (let c = 0; c < 3; ++c) out[at + c] = pale[c] + (to[c] - pale[c]) * w;
  }

  // The pane of a canvas under client point (x, y) when it shows `panes` sources side by side:
  // its index and its rectangle on the screen.
  function paneAt(canvas, panes, clientX) {
    const rect = canvas.getBoundingClientRect();
    const width = rect.width / panes;
    const index = Math.max(0, Math.min(panes - 1, Math.floor((clientX - rect.left) / width)));
    return { index, rect: { left: rect.left + index * width, top: rect.top, width, height: rect.height } };
  }

  function paneRect(canvas, panes, index) {
    const rect = canvas.getBoundingClientRect();
    const width = rect.width / panes;
    return { left: rect.left + index * width, top: rect.top, width, height: rect.height };
  }

  function makeView(canvas, labels) {
    let renderer = null;
    try {
      renderer = typeof THREE === 'undefined' ? null : new THREE.WebGLRenderer({ canvas, antialias: true });
    } catch (e) {
      renderer = null;
    }
    if (!renderer || !renderer.getContext()) return makeCanvasView(canvas, labels);
    return makeWebGLView(canvas, renderer, labels);
  }

  function makeWebGLView(canvas, renderer, labels) {
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

    // Front and back of the cloth in different colours, both lit (two-sided lighting); or both
    // sides coloured by strain.
    const materials = {
      front: new THREE.MeshPhongMaterial({ color: 0xc8553d, side: THREE.FrontSide, shininess: 20 }),
      back: new THREE.MeshPhongMaterial({ color: 0x3d7ec8, side: THREE.BackSide, shininess: 20 }),
      strain: new THREE.MeshPhongMaterial({ color: 0xffffff, side: THREE.DoubleSide, shininess: 20,
                                            vertexColors: THREE.VertexColors }),
      springs: new THREE.LineBasicMaterial({ color: 0x333333 }),
      points: new THREE.PointsMaterial({ color: 0xc8553d, size: 6, sizeAttenuation: false }),
      pins: new THREE.PointsMaterial({ color: 0x111111, size: 7, sizeAttenuation: false }),
      trail: new THREE.LineBasicMaterial({ color: 0x1f4e79, transparent: true, opacity: 0.5 }),
      solid: new THREE.MeshPhongMaterial({ color: 0x9aa3ab }),
      plane: new THREE.MeshPhongMaterial({ color: 0x9aa3ab, side: THREE.DoubleSide, transparent: true, opacity: 0.55 }),
    };
    const settings = { strain: false, strainScale: 0.1, springs: false };
    // How far the camera stands back, as a multiple of the distance that frames the box in a
    // pane at least as wide as it is tall (see fit).
    let fitted = 1;
    let bodies = [];   // one per source: its meshes and how many triangles and springs it has
    let fixtures = []; // the ground, planes and spheres
    let sources = [];

    function makeBody(source) {
      const n = source.count();
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
      geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * n).fill(1), 3));
      const body = { source, geometry, objects: [], triangles: -1, springs: -1 };
      body.front = new THREE.Mesh(geometry, materials.front);
      body.back = new THREE.Mesh(geometry, materials.back);
      body.front.castShadow = body.back.castShadow = true;
      const lineGeometry = new THREE.BufferGeometry();
      lineGeometry.setAttribute('position', geometry.getAttribute('position'));
      body.lines = new THREE.LineSegments(lineGeometry, materials.springs);
      body.points = new THREE.Points(geometry, materials.points);
      // Pins, and the particle the mouse holds, as dots.
      body.pins = new THREE.Points(new THREE.BufferGeometry(), materials.pins);
      body.objects = [body.front, body.back, body.lines, body.points, body.pins];
      if (source.trails) {
        body.trails = [];
        for (let i = 0; i < n; ++i) body.trails.push(new THREE.Line(new THREE.BufferGeometry(), materials.trail));
        body.objects.push(...body.trails);
      }
      scene.add(...body.objects);
      topology(body);
      return body;
    }

    // The surface and the springs, again when a tear has changed them.
    function topology(body) {
      const tris = body.source.triangles(), springs = body.source.springs();
      if (tris.length !== body.triangles) {
        body.geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(tris), 1));
        body.triangles = tris.length;
      }
      if (springs.length !== body.springs) {
        body.lines.geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(springs), 1));
        body.springs = springs.length;
      }
    }

    function showBody(body, on) {
      const cloth = body.triangles > 0;
      body.front.visible = on && cloth;
      body.back.visible = on && cloth && !settings.strain;
      body.front.material = settings.strain ? materials.strain : materials.front;
      body.lines.visible = on && (!cloth || settings.springs);
      body.points.visible = on && !cloth;
      body.pins.visible = on;
      for (const trail of body.trails || []) trail.visible = on;
    }

    function clear() {
      for (const o of bodies.flatMap((b) => b.objects).concat(fixtures)) scene.remove(o);
      bodies = [];
      fixtures = [];
    }

    // Builds the scene for `list` (one or two sources); `keepCamera` keeps the user's view.
    function rebuild(list, keepCamera) {
      clear();
      sources = list;
      bodies = list.map(makeBody);
      const box = list[0].bounds ? list[0].bounds() : framed(list[0]);
      const colliders = list[0].colliders();
      const groundY = colliders.ground !== null && colliders.ground !== undefined
        ? colliders.ground : box.lo[1] - 0.5 * box.size;
      const size = Math.max(box.size, 1e-3);
      // The ground (a grid with the cloth's shadow), from the scene's [ground], else below it.
      const grid = new THREE.GridHelper(size * 4, 20, 0x888888, 0xbbbbbb);
      grid.position.set(box.centre[0], groundY, box.centre[2]);
      const floor = new THREE.Mesh(new THREE.PlaneGeometry(size * 4, size * 4), new THREE.ShadowMaterial({ opacity: 0.25 }));
      floor.rotation.x = -Math.PI / 2;
      floor.position.set(box.centre[0], groundY + size * 1e-3, box.centre[2]);
      floor.receiveShadow = true;
      fixtures.push(grid, floor);
      // Each plane (a ramp): a square of it around the point nearest the cloth's centre.
      for (const p of colliders.planes) {
        const normal = new THREE.Vector3(...p.normal).normalize();
        const centre = new THREE.Vector3(...box.centre);
        const off = centre.clone().sub(new THREE.Vector3(...p.point)).dot(normal);
        const patch = new THREE.Mesh(new THREE.PlaneGeometry(size * 3, size * 3), materials.plane);
        patch.position.copy(centre.sub(normal.clone().multiplyScalar(off + size * 1e-3)));
        patch.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), normal);
        patch.receiveShadow = true;
        fixtures.push(patch);
      }
      // Each sphere, a little smaller than it is so that the cloth on it shows.
      for (const s of colliders.spheres) {
        const ball = new THREE.Mesh(new THREE.SphereGeometry(0.98 * s.radius, 48, 24), materials.solid);
        ball.position.set(...s.centre);
        ball.castShadow = ball.receiveShadow = true;
        fixtures.push(ball);
      }
      scene.add(...fixtures);
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
        fitted = 1;
      }
      update();
    }

    // The camera's field of view is vertical: a pane narrower than it is tall (each half of
    // the side-by-side split) sees less across than the box the camera was placed for, and the
    // cloth's pinned edges fall outside it. Backed off by 1 / aspect there, the camera sees as
    // much across as in a square pane; the user's own zoom and orbit are kept, scaled alike.
    function fit(aspect) {
      const wanted = Math.max(1, 1 / Math.max(aspect, 1e-3));
      if (wanted === fitted) return;
      const offset = camera.position.clone().sub(controls.target);
      camera.position.copy(controls.target).add(offset.multiplyScalar(wanted / fitted));
      fitted = wanted;
    }

    function update() {
      for (const body of bodies) {
        const x = body.source.positions();
        if (x.length !== body.geometry.getAttribute('position').array.length) continue;
        topology(body);
        const attribute = body.geometry.getAttribute('position');
        attribute.array.set(x);
        attribute.needsUpdate = true;
        if (body.triangles > 0) body.geometry.computeVertexNormals();
        body.geometry.computeBoundingSphere();
        if (settings.strain) {
          const strain = body.source.strains();
          const colour = body.geometry.getAttribute('color');
          for (let i = 0; i < strain.length; ++i) strainColour(strain[i], settings.strainScale, colour.array, 3 * i);
          colour.needsUpdate = true;
        }
        const pins = [];
        for (let i = 0; i < x.length / 3; ++i) if (body.source.isPinned(i)) pins.push(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
        body.pins.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pins), 3));
        if (body.trails) {
          const history = body.source.trails();
          body.trails.forEach((trail, i) => {
            const path = new Float32Array(3 * history.length);
            history.forEach((frame, f) => path.set(frame.subarray(3 * i, 3 * i + 3), 3 * f));
            trail.geometry.setAttribute('position', new THREE.BufferAttribute(path, 3));
          });
        }
      }
    }

    function draw() {
      const w = canvas.clientWidth, h = canvas.clientHeight;
      if (canvas.width !== w || canvas.height !== h) renderer.setSize(w, h, false);
      const panes = Math.max(bodies.length, 1);
      camera.aspect = w / panes / Math.max(h, 1);
      camera.updateProjectionMatrix();
      fit(camera.aspect);
      controls.update();
      renderer.setScissorTest(panes > 1);
      for (let k = 0; k < panes; ++k) {
        bodies.forEach((body, b) => showBody(body, b === k));
        const left = Math.round(k * w / panes), width = Math.round((k + 1) * w / panes) - left;
        renderer.setViewport(left, 0, width, h);
        renderer.setScissor(left, 0, width, h);
        renderer.render(scene, camera);
      }
      showLabels(labels, panes);
    }

    // Screen point of a world point seen in pane `rect`.
    function toScreen(point, rect) {
      const p = new THREE.Vector3(...point).project(camera);
      return [rect.left + (p.x + 1) / 2 * rect.width, rect.top + (1 - p.y) / 2 * rect.height];
    }

    // The particle nearest the mouse (within a few pixels) in the pane under it, or -1.
    function pick(clientX, clientY) {
      const pane = paneAt(canvas, Math.max(bodies.length, 1), clientX);
      const x = sources[pane.index].positions();
      let best = -1, bestDistance = 12;  // [px]
      for (let i = 0; i < x.length / 3; ++i) {
        const [sx, sy] = toScreen([x[3 * i], x[3 * i + 1], x[3 * i + 2]], pane.rect);
        const d = Math.hypot(sx - clientX, sy - clientY);
        if (d < bestDistance) { bestDistance = d; best = i; }
      }
      return best;
    }

    // Where the mouse points on the plane through `point` facing the camera.
    function pointOnPlane(clientX, clientY, point) {
      const { rect } = paneAt(canvas, Math.max(bodies.length, 1), clientX);
      const ndc = new THREE.Vector2((clientX - rect.left) / rect.width * 2 - 1, -(clientY - rect.top) / rect.height * 2 + 1);
      const ray = new THREE.Raycaster();
      ray.setFromCamera(ndc, camera);
      const normal = new THREE.Vector3();
      camera.getWorldDirection(normal);
      const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, new THREE.Vector3(...point));
      const hit = new THREE.Vector3();
      return ray.ray.intersectPlane(plane, hit) ? [hit.x, hit.y, hit.z] : null;
    }

    // Where particle i of source `pane` is on the screen [px].
    function screenOf(i, pane = 0) {
      const x = sources[pane].positions();
      return toScreen([x[3 * i], x[3 * i + 1], x[3 * i + 2]], paneRect(canvas, Math.max(bodies.length, 1), pane));
    }

    return { kind: 'webgl', rebuild, update, draw, pick, pointOnPlane, screenOf, controls, settings };
  }

  // The pane labels over the canvas ("your code", "reference"), shown when there are two panes.
  function showLabels(labels, panes) {
    if (!labels) return;
    labels.forEach((label, k) => {
      label.style.display = panes > 1 ? 'block' : 'none';
      label.style.left = `${(100 * k) / panes + 1}%`;
    });
  }

  // Without WebGL: the particles and springs drawn flat on a 2D canvas, seen from the front,
  // strained springs in colour when asked for.
  function makeCanvasView(canvas, labels) {
    const g = canvas.getContext('2d');
    let box = null;
    let sources = [];
    const settings = { strain: false, strainScale: 0.1, springs: false };
    const scale = (panes) => 0.8 * Math.min(canvas.width / panes, canvas.height) / Math.max(box.size, 1e-9);
    const screen = (x, i, pane, panes) => {
      const w = canvas.width / panes, s = scale(panes);
      return [pane * w + w / 2 + s * (x[3 * i] - box.centre[0]), canvas.height / 2 - s * (x[3 * i + 1] - box.centre[1])];
    };
    const panes = () => Math.max(sources.length, 1);
    return {
      kind: '2d',
      settings,
      rebuild(list) { sources = list; box = list[0].bounds ? list[0].bounds() : framed(list[0]); },
      update() {},
      draw() {
        canvas.width = canvas.clientWidth;
        canvas.height = canvas.clientHeight;
        g.clearRect(0, 0, canvas.width, canvas.height);
        sources.forEach((source, pane) => {
          const x = source.positions();
          const tris = source.triangles();
          g.strokeStyle = '#c8553d';
          g.beginPath();
          for (let k = 0; k < tris.length; k += 3) {
            const a = screen(x, tris[k], pane, panes()), b = screen(x, tris[k + 1], pane, panes());
            const c = screen(x, tris[k + 2], pane, panes());
            g.moveTo(...a); g.lineTo(...b); g.lineTo(...c); g.closePath();
          }
          g.stroke();
          if (settings.strain || settings.springs || !tris.length) {
            const springs = source.springs(), strain = settings.strain ? source.strains() : null;
            const rgb = [0, 0, 0];
            for (let k = 0; k < springs.length; k += 2) {
              if (strain) strainColour(Math.max(strain[springs[k]], strain[springs[k + 1]]), settings.strainScale, rgb, 0);
              g.strokeStyle = strain ? `rgb(${rgb.map((c) => Math.round(255 * c)).join(',')})` : '#333';
              g.beginPath();
              g.moveTo(...screen(x, springs[k], pane, panes()));
              g.lineTo(...screen(x, springs[k + 1], pane, panes()));
              g.stroke();
            }
          }
          g.fillStyle = '#222';
          for (let i = 0; i < x.length / 3; ++i) g.fillRect(...screen(x, i, pane, panes()).map((v) => v - 1.5), 3, 3);
        });
        showLabels(labels, panes());
      },
      pick(clientX, clientY) {
        const pane = paneAt(canvas, panes(), clientX).index;
        const x = sources[pane].positions();
        let best = -1, bestDistance = 12;
        for (let i = 0; i < x.length / 3; ++i) {
          const [sx, sy] = this.screenOf(i, pane);
          const d = Math.hypot(sx - clientX, sy - clientY);
          if (d < bestDistance) { bestDistance = d; best = i; }
        }
        return best;
      },
      screenOf(i, pane = 0) {
        const rect = canvas.getBoundingClientRect();
        const [sx, sy] = screen(sources[pane].positions(), i, pane, panes());
        return [rect.left + sx, rect.top + sy];
      },
      pointOnPlane(clientX, clientY, point) {
        const { rect } = paneAt(canvas, panes(), clientX);
        const s = scale(panes());
        return [box.centre[0] + (clientX - rect.left - rect.width / 2) / s,
                box.centre[1] - (clientY - rect.top - rect.height / 2) / s, point[2]];
      },
      controls: null,
    };
  }

  return { makeView, bounds, strainColour };
})();
