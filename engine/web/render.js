// render.js: draws one cloth, or two side by side, with three.js (WebGL), or with a painter of
// its own on a 2D canvas where WebGL is missing, and plots the energies. The live pages (live.js) give it their
// engines as *sources*, and the recorded-run viewer (engine/io/viewer.html) its frames:
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

  // Without WebGL: each source painted on the 2D canvas, seen from an orbiting camera with a
  // gentle perspective: the triangles flat-shaded by how squarely they face a light over the
  // viewer's shoulder (both sides lit alike: cloth has no inside; coloured by strain when asked
  // for), farthest first (the painter's algorithm), with the ground's grid, the planes, the
  // spheres, the springs, the pins and, where the source gives them, the particles' trails. A
  // few thousand triangles a frame; it needs no library.
  function makeCanvasView(canvas, labels) {
    const g = canvas.getContext('2d');
    const settings = { strain: false, strainScale: 0.1, springs: false };
    const camera = { yaw: 0.6, pitch: 0.35, zoom: 1 };
    let box = null;
    let sources = [];
    const panes = () => Math.max(sources.length, 1);
    const radius = () => Math.max(1e-6, Math.hypot(box.hi[0] - box.lo[0], box.hi[1] - box.lo[1], box.hi[2] - box.lo[2]) / 2);

    // The pane `index` of the canvas, in canvas pixels: its left edge, size and scale [px/m].
    function paneView(index) {
      const w = canvas.width / panes(), h = canvas.height;
      return { left: index * w, w, h, scale: camera.zoom * 0.42 * Math.min(w, h) / radius() };
    }
    // World point -> [x, y, depth] in the pane's canvas pixels. y is up in the world and down
    // on the screen.
    function project(p, view) {
      const c = box.centre, r = radius();
      const x = p[0] - c[0], y = p[1] - c[1], z = p[2] - c[2];
      const cx = Math.cos(camera.yaw) * x - Math.sin(camera.yaw) * z;
      const cz = Math.sin(camera.yaw) * x + Math.cos(camera.yaw) * z;
      const cy = Math.cos(camera.pitch) * y - Math.sin(camera.pitch) * cz;
      const depth = Math.sin(camera.pitch) * y + Math.cos(camera.pitch) * cz;
      const scale = view.scale / (1 + depth / (4 * r));
      return [view.left + view.w / 2 + cx * scale, view.h / 2 - cy * scale, depth];
    }
    // The world point that projects to canvas pixel (sx, sy) at `depth`: project's inverse.
    function unproject(sx, sy, depth, view) {
      const scale = view.scale / (1 + depth / (4 * radius()));
      const cx = (sx - view.left - view.w / 2) / scale, cy = (view.h / 2 - sy) / scale;
      const sp = Math.sin(camera.pitch), cp = Math.cos(camera.pitch);
      const sw = Math.sin(camera.yaw), cw = Math.cos(camera.yaw);
      const y = cp * cy + sp * depth, cz = -sp * cy + cp * depth;
      const x = cw * cx + sw * cz, z = -sw * cx + cw * cz;
      return [box.centre[0] + x, box.centre[1] + y, box.centre[2] + z];
    }

    // A grid of lines in the plane through `origin` spanned by unit vectors u and v.
    function grid(origin, u, v, view) {
      const span = 1.2 * radius(), step = span / 10;
      const at = (a, b) => project([0, 1, 2].map((k) => origin[k] + a * u[k] + b * v[k]), view);
      g.strokeStyle = 'rgba(120, 110, 90, 0.35)';
      g.lineWidth = devicePixelRatio;
      g.beginPath();
      for (let k = -10; k <= 10; ++k) {
        const a = at(k * step, -span), b = at(k * step, span), d = at(-span, k * step), e = at(span, k * step);
        g.moveTo(a[0], a[1]); g.lineTo(b[0], b[1]);
        g.moveTo(d[0], d[1]); g.lineTo(e[0], e[1]);
      }
      g.stroke();
    }

    function paint(source, view) {
      const x = source.positions(), n = x.length / 3;
      const tris = source.triangles(), springs = source.springs();
      const p = (i) => [x[3 * i], x[3 * i + 1], x[3 * i + 2]];
      const screen = new Array(n);
      for (let i = 0; i < n; ++i) screen[i] = project(p(i), view);
      const c = box.centre;
      const colliders = source.colliders();
      if (colliders.ground !== null && colliders.ground !== undefined) {
        grid([c[0], colliders.ground, c[2]], [1, 0, 0], [0, 0, 1], view);
      }
      // A plane (a ramp): the grid laid in it around the point nearest the box's centre.
      const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
      const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
      const unit = (a) => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; };
      for (const plane of colliders.planes) {
        const nn = unit(plane.normal);
        const t1 = unit(Math.abs(nn[1]) < 0.9 ? cross(nn, [0, 1, 0]) : cross(nn, [1, 0, 0]));
        const off = dot([c[0] - plane.point[0], c[1] - plane.point[1], c[2] - plane.point[2]], nn);
        grid([c[0] - off * nn[0], c[1] - off * nn[1], c[2] - off * nn[2]], t1, cross(nn, t1), view);
      }

      // Triangles and spheres, farthest first.
      const order = [];
      for (let t = 0; t < tris.length; t += 3) {
        order.push([t, screen[tris[t]][2] + screen[tris[t + 1]][2] + screen[tris[t + 2]][2]]);
      }
      for (const sphere of colliders.spheres) {
        const q = project(sphere.centre, view);
        order.push([{ sphere, at: q }, 3 * q[2]]);  // its centre, on the triangles' scale
      }
      order.sort((a, b) => b[1] - a[1]);
      const light = [0.3, 0.8, 0.5];
      const strain = settings.strain ? source.strains() : null;
      const rgb = [0, 0, 0];
      for (const [t] of order) {
        if (typeof t === 'object') {  // a sphere: a shaded disc
          const s = t.sphere;
          const edge = project([s.centre[0] + s.radius, s.centre[1], s.centre[2]], view);
          const r = Math.hypot(edge[0] - t.at[0], edge[1] - t.at[1]) || 1;
          const shade = g.createRadialGradient(t.at[0] - r / 3, t.at[1] - r / 3, r / 10, t.at[0], t.at[1], r);
          shade.addColorStop(0, '#e8dcc8');
          shade.addColorStop(1, '#9c8a6c');
          g.fillStyle = shade;
          g.beginPath();
          g.arc(t.at[0], t.at[1], r, 0, 2 * Math.PI);
          g.fill();
          continue;
        }
        const a = p(tris[t]), b = p(tris[t + 1]), d = p(tris[t + 2]);
        const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]], v = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        const nrm = cross(u, v);
        const lit = Math.abs(dot(nrm, light)) / (Math.hypot(...nrm) || 1);
        if (strain) {
          strainColour((strain[tris[t]] + strain[tris[t + 1]] + strain[tris[t + 2]]) / 3, settings.strainScale, rgb, 0);
          const k = 0.55 + 0.45 * lit;
          g.fillStyle = `rgb(${rgb.map((q) => Math.round(255 * k * q)).join(',')})`;
        } else {
          const shade = Math.round(90 + 150 * lit);
          g.fillStyle = `rgb(${Math.round(shade * 0.55)}, ${Math.round(shade * 0.7)}, ${shade})`;
        }
        g.strokeStyle = g.fillStyle;
        g.beginPath();
        for (const i of [tris[t], tris[t + 1], tris[t + 2]]) g.lineTo(screen[i][0], screen[i][1]);
        g.closePath();
        g.fill();
        g.stroke();  // closes the hairline gaps between neighbouring triangles
      }
      if (settings.springs || tris.length === 0) {
        g.lineWidth = devicePixelRatio;
        for (let s = 0; s < springs.length; s += 2) {
          if (strain) strainColour(Math.max(strain[springs[s]], strain[springs[s + 1]]), settings.strainScale, rgb, 0);
          g.strokeStyle = strain ? `rgb(${rgb.map((q) => Math.round(255 * q)).join(',')})` : 'rgba(40, 40, 40, 0.5)';
          g.beginPath();
          g.moveTo(screen[springs[s]][0], screen[springs[s]][1]);
          g.lineTo(screen[springs[s + 1]][0], screen[springs[s + 1]][1]);
          g.stroke();
        }
      }
      // The path each particle has taken so far (a scene of a few free particles).
      if (source.trails) {
        g.strokeStyle = 'rgba(31, 78, 121, 0.45)';
        g.lineWidth = 1.5 * devicePixelRatio;
        const history = source.trails();
        for (let i = 0; i < n; ++i) {
          g.beginPath();
          for (const frame of history) {
            const q = project([frame[3 * i], frame[3 * i + 1], frame[3 * i + 2]], view);
            g.lineTo(q[0], q[1]);
          }
          g.stroke();
        }
      }
      // Pins, and the particles of a scene without triangles, as dots.
      const size = 3 * devicePixelRatio;
      for (let i = 0; i < n; ++i) {
        const pinned = source.isPinned(i);
        if (tris.length && !pinned) continue;
        g.fillStyle = pinned ? '#c0392b' : '#1f4e79';
        g.beginPath();
        g.arc(screen[i][0], screen[i][1], pinned ? 1.6 * size : size, 0, 2 * Math.PI);
        g.fill();
      }
    }

    // Client point -> canvas pixels, and back.
    const ratio = () => canvas.width / Math.max(canvas.getBoundingClientRect().width, 1);

    return {
      kind: '2d',
      settings,
      camera,
      rebuild(list) { sources = list; box = list[0].bounds ? list[0].bounds() : framed(list[0]); },
      update() {},
      draw() {
        canvas.width = canvas.clientWidth * devicePixelRatio;
        canvas.height = canvas.clientHeight * devicePixelRatio;
        g.fillStyle = '#f4f4f1';
        g.fillRect(0, 0, canvas.width, canvas.height);
        sources.forEach((source, index) => {
          const view = paneView(index);
          g.save();
          g.beginPath();
          g.rect(view.left, 0, view.w, view.h);
          g.clip();
          paint(source, view);
          g.restore();
        });
        showLabels(labels, panes());
      },
      // Turns the camera (the mouse's drag) and moves it nearer or farther (the wheel).
      orbit(dx, dy) {
        camera.yaw += dx;
        camera.pitch = Math.max(-1.5, Math.min(1.5, camera.pitch + dy));
      },
      zoomBy(factor) { camera.zoom *= factor; },
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
        const rect = canvas.getBoundingClientRect(), k = ratio();
        const x = sources[pane].positions();
        const [sx, sy] = project([x[3 * i], x[3 * i + 1], x[3 * i + 2]], paneView(pane));
        return [rect.left + sx / k, rect.top + sy / k];
      },
      // Where the mouse points on the plane through `point` facing the camera.
      pointOnPlane(clientX, clientY, point) {
        const rect = canvas.getBoundingClientRect(), k = ratio();
        const view = paneView(paneAt(canvas, panes(), clientX).index);
        const depth = project(point, view)[2];
        return unproject((clientX - rect.left) * k, (clientY - rect.top) * k, depth, view);
      },
      controls: null,
    };
  }

  // A number as the pages print it: four significant digits, or an exponent when very large or
  // small.
  function formatValue(v) {
    if (v === 0) return '0';
    const a = Math.abs(v);
    return a >= 1e4 || a < 1e-3 ? v.toExponential(3) : String(Number(v.toPrecision(4)));
  }

  // The energy plot, on a 2D canvas of its own: kinetic (red), potential (blue) and their sum
  // (black) against time t [s], with the range's ends in joules. options.at marks one time (the
  // recorded-run viewer's frame); options.stopped marks the right end in red (a run the guard
  // stopped there).
  function plotEnergy(canvas, t, kinetic, potential, options = {}) {
    const g = canvas.getContext('2d');
    g.clearRect(0, 0, canvas.width, canvas.height);
    const n = t.length;
    if (n < 2) return;
    const total = kinetic.map((k, i) => k + potential[i]);
    let lo = Infinity, hi = -Infinity;
    for (const series of [kinetic, potential, total]) {
      for (const v of series) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    }
    if (!(hi - lo >= 1e-12)) { hi = (Number.isFinite(hi) ? hi : 0) + 1; lo = hi - 2; }
    const span = Math.max(t[n - 1] - t[0], 1e-12);
    const x = (time) => 4 + (canvas.width - 8) * (time - t[0]) / span;
    const y = (v) => canvas.height - 4 - (canvas.height - 8) * (v - lo) / (hi - lo);
    const line = (values, colour) => {
      g.strokeStyle = colour;
      g.beginPath();
      values.forEach((v, i) => (i ? g.lineTo(x(t[i]), y(v)) : g.moveTo(x(t[i]), y(v))));
      g.stroke();
    };
    line(kinetic, '#c0392b');
    line(potential, '#2c6e9e');
    line(total, '#222');
    g.fillStyle = '#555';
    g.font = '10px monospace';
    g.fillText(`${formatValue(hi)} J`, 6, 12);
    g.fillText(`${formatValue(lo)} J`, 6, canvas.height - 6);
    if (options.stopped) {
      g.fillStyle = '#c0392b';
      g.fillRect(canvas.width - 3, 0, 3, canvas.height);
    }
    if (options.at !== undefined) {
      g.fillStyle = 'rgba(0, 0, 0, 0.25)';
      g.fillRect(x(options.at) - 1, 0, 2, canvas.height);
    }
  }

  return { makeView, bounds, strainColour, formatValue, plotEnergy };
})();
