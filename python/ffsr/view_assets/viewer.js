// The 3-D view of a capture (ffsr.view): builds a three.js scene from the page's data (the main
// job's result and its time series, prepared by ffsr/view.py) and animates it. Classic script: it
// defines window.ffsrView(THREE, OrbitControls, data); the page's loader imports the vendored
// three.js module and calls it.
//
// Frames: the inertial frame o of the result, z up on the screen. Every pose of the data is
// x, y, z, qw, qx, qy, qz (the series' columns). Colours: the figures' Okabe-Ito palette.
'use strict';

window.ffsrView = function (THREE, OrbitControls, data) {
  const COLOURS = {
    baseline: 0x0072b2, optimized: 0xd55e00, global: 0x009e73,  // the runs, as in the figures
    target: 0xcc79a7, reconfiguration: 0xe69f00, normal: 0x882255, bus: 0x9aa4b1, busEdge: 0x4b5360,
    link: 0xdfe3e8, detumble: 0x56b4e9,
  };
  const hex = (c) => '#' + c.toString(16).padStart(6, '0');

  // --- the page ----------------------------------------------------------------------------------
  const $ = (id) => document.getElementById(id);
  const canvasBox = $('view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(canvasBox.clientWidth, canvasBox.clientHeight);
  canvasBox.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf3f4f6);
  const camera = new THREE.PerspectiveCamera(35, canvasBox.clientWidth / canvasBox.clientHeight, 0.01, 1000);
  camera.up.set(0, 0, 1);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x9aa0a8, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 2.0);
  scene.add(sun);

  // --- data helpers --------------------------------------------------------------------------------
  const runs = data.runs;
  // the capture instant of a run, and the last time it shows (after the capture with a post-capture run)
  const captureTime = (r) => r.t[r.capture_index];
  const endTime = (r) => r.t[r.t.length - 1];
  const hasPost = (r) => r.capture_index < r.t.length - 1;
  const bodies = data.bodies;
  const nb = bodies.length;
  const v3 = (a, k = 0) => new THREE.Vector3(a[k], a[k + 1], a[k + 2]);
  const quat = (a, k) => new THREE.Quaternion(a[k + 4], a[k + 5], a[k + 6], a[k + 3]);  // w x y z -> x y z w
  const setPose = (obj, a, k) => {
    obj.position.set(a[k], a[k + 1], a[k + 2]);
    obj.quaternion.set(a[k + 4], a[k + 5], a[k + 6], a[k + 3]);
  };

  // the pose arrays of one frame k of run r, body b (0: the base)
  const bodyPose = (r, b, k) => (b === 0 ? [r.base, 7 * k] : [r.bodies, 7 * ((nb - 1) * k + b - 1)]);

  // The extent of everything over every run: camera, grid and sizes.
  const box = new THREE.Box3();
  for (const r of runs) {
    const n = r.t.length;
    for (let k = 0; k < n; ++k) {
      for (let b = 0; b < nb; ++b) {
        const [a, i] = bodyPose(r, b, k);
        box.expandByPoint(v3(a, i));
      }
      box.expandByPoint(v3(r.target, 7 * k));
    }
  }
  const extent = box.getSize(new THREE.Vector3());
  // the arm's size: the longest chain of joint offsets (for line widths and marker sizes)
  let reach = 0;
  {
    const r = runs[0];
    for (let b = 1; b < nb; ++b) {
      const p = bodies[b].parent;
      const [a, i] = bodyPose(r, b, 0);
      const [c, j] = bodyPose(r, p, 0);
      reach += v3(a, i).distanceTo(v3(c, j));
    }
    reach = Math.max(reach, 0.5);
  }
  const lineRadius = 0.012 * reach;

  // --- geometry of shapes -------------------------------------------------------------------------
  const material = (colour, opts = {}) =>
    new THREE.MeshStandardMaterial(Object.assign({ color: colour, metalness: 0.15, roughness: 0.55 }, opts));

  function shapeMesh(s, mat) {
    let g;
    if (s.kind === 'box') g = new THREE.BoxGeometry(s.size[0], s.size[1], s.size[2]);
    else if (s.kind === 'sphere') g = new THREE.SphereGeometry(s.radius, 32, 16);
    else if (s.kind === 'cylinder') g = new THREE.CylinderGeometry(s.radius, s.radius, s.length, 32).rotateX(Math.PI / 2);
    else if (s.kind === 'capsule') g = new THREE.CapsuleGeometry(s.radius, s.length, 8, 24).rotateX(Math.PI / 2);
    else throw new Error('ffsr.view: unknown shape kind ' + s.kind);
    const m = new THREE.Mesh(g, mat);
    const p = s.position, q = s.quaternion_wxyz;
    m.position.set(p[0], p[1], p[2]);
    m.quaternion.set(q[1], q[2], q[3], q[0]);
    return m;
  }
  function withEdges(mesh, colour) {
    const e = new THREE.LineSegments(new THREE.EdgesGeometry(mesh.geometry, 30),
                                     new THREE.LineBasicMaterial({ color: colour }));
    e.position.copy(mesh.position);
    e.quaternion.copy(mesh.quaternion);
    e.userData.role = 'edges';
    return e;
  }

  // An arrow from its tail along +z of its group, length L: shaft and head as meshes.
  function arrow(L, radius, colour) {
    const g = new THREE.Group();
    const mat = material(colour, { roughness: 0.4 });
    const head = Math.min(0.3 * L, 8 * radius);
    const shaft = new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, L - head, 16).rotateX(Math.PI / 2), mat);
    shaft.position.z = (L - head) / 2;
    const cone = new THREE.Mesh(new THREE.ConeGeometry(2.6 * radius, head, 24).rotateX(Math.PI / 2), mat);
    cone.position.z = L - head / 2;
    g.add(shaft, cone);
    return g;
  }

  // --- the robot ----------------------------------------------------------------------------------
  const hasShapes = bodies.some((b) => b.shapes.length > 0);
  const bodyGroups = [];  // one group per body, posed from the series
  for (let b = 0; b < nb; ++b) {
    const g = new THREE.Group();
    g.userData.role = b === 0 ? 'base-frame' : 'body-frame';
    scene.add(g);
    bodyGroups.push(g);
  }
  const linkMaterial = material(COLOURS.link, { metalness: 0.25, roughness: 0.4 });
  const jointMaterial = material(0x30343a, { roughness: 0.35 });
  const busMaterial = material(COLOURS.bus, { metalness: 0.35, roughness: 0.45 });

  // the bus: its shapes, else a box around the base frame whose half side reaches the farthest mount
  if (bodies[0].shapes.length > 0) {
    for (const s of bodies[0].shapes) {
      const m = shapeMesh(s, busMaterial);
      m.userData.role = 'bus';
      bodyGroups[0].add(m, withEdges(m, COLOURS.busEdge));
    }
  } else {
    const r = runs[0];
    const base = v3(r.base, 0), q0 = quat(r.base, 0).invert();
    let half = 0.05;
    for (let b = 1; b < nb; ++b) {
      if (bodies[b].parent !== 0) continue;
      const [a, i] = bodyPose(r, b, 0);
      const local = v3(a, i).sub(base).applyQuaternion(q0);
      half = Math.max(half, Math.abs(local.x), Math.abs(local.y), Math.abs(local.z));
    }
    const m = new THREE.Mesh(new THREE.BoxGeometry(2 * half, 2 * half, 2 * half), busMaterial);
    m.userData.role = 'bus';
    bodyGroups[0].add(m, withEdges(m, COLOURS.busEdge));
  }

  // the links: their shapes (in the body frames), else segments between the joint origins, each
  // joint a marker; the end-effector's body also reaches its end-effector point
  const segments = [];  // {from: body, to: body or 'ee', mesh}
  const unitCylinder = new THREE.CylinderGeometry(1, 1, 1, 20).rotateX(Math.PI / 2).translate(0, 0, 0.5);
  if (hasShapes) {
    for (let b = 1; b < nb; ++b)
      for (const s of bodies[b].shapes) {
        const m = shapeMesh(s, linkMaterial);
        m.userData.role = 'link';
        bodyGroups[b].add(m);
      }
  } else {
    const addSegment = (from, to) => {
      const m = new THREE.Mesh(unitCylinder, linkMaterial);
      m.userData.role = 'link';
      scene.add(m);
      segments.push({ from, to, mesh: m });
    };
    for (let b = 1; b < nb; ++b) if (bodies[b].parent > 0) addSegment(bodies[b].parent, b);
    addSegment(data.end_effector_body, 'ee');
  }
  for (let b = 1; b < nb; ++b) {  // joint markers: always (on top of shapes they show the joints)
    if (hasShapes) continue;
    const m = new THREE.Mesh(new THREE.SphereGeometry(1.9 * lineRadius, 24, 12), jointMaterial);
    m.userData.role = 'joint';
    bodyGroups[b].add(m);
  }
  const eeMarker = new THREE.Mesh(new THREE.SphereGeometry(1.5 * lineRadius, 24, 12), material(0x222222));
  eeMarker.userData.role = 'end-effector';
  scene.add(eeMarker);

  // --- the target ---------------------------------------------------------------------------------
  const targetGroup = new THREE.Group();
  targetGroup.userData.role = 'target-frame';
  scene.add(targetGroup);
  const tshape = data.target_shape;
  {
    const m = shapeMesh(tshape, material(COLOURS.target, { transparent: true, opacity: 0.72, roughness: 0.7 }));
    m.userData.role = 'target';
    m.userData.kind = tshape.kind;
    targetGroup.add(m, withEdges(m, 0x7a3b63));
  }
  const rtp = v3(data.contact_offset), un = v3(data.contact_normal_target_frame).normalize();
  const arrowLength = Math.max(0.18 * reach, 0.15);
  const normalArrow = arrow(arrowLength, 0.45 * lineRadius, COLOURS.normal);
  // the normal points from the end-effector into the target: the arrow arrives at the contact point
  normalArrow.position.copy(rtp.clone().addScaledVector(un, -arrowLength));
  normalArrow.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), un);
  normalArrow.userData.role = 'contact-normal';
  targetGroup.add(normalArrow);
  const contactPoint = new THREE.Mesh(new THREE.SphereGeometry(1.1 * lineRadius, 20, 10), material(COLOURS.normal));
  contactPoint.position.copy(rtp);
  contactPoint.userData.role = 'contact-point';
  targetGroup.add(contactPoint);

  // the capture point (where the contact point is at the capture instant): a ring across the normal
  const capture = new THREE.Mesh(new THREE.TorusGeometry(3.2 * lineRadius, 0.35 * lineRadius, 12, 48),
                                 material(COLOURS.normal, { emissive: 0x3a0f25 }));
  capture.position.copy(v3(data.capture_point));
  capture.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), v3(data.capture_normal).normalize());
  capture.userData.role = 'capture-point';
  scene.add(capture);

  // --- the grid under the scene -------------------------------------------------------------------
  const size = Math.max(extent.x, extent.y, 1) * 1.8;
  const decade = Math.pow(10, Math.floor(Math.log10(size / 8)));  // a line every 1, 2 or 5 x 10^k m, ~8 of them
  const step = [1, 2, 5, 10].map((f) => f * decade).find((x) => size / x <= 10);
  const divisions = Math.max(2, Math.round(size / step));
  const grid = new THREE.GridHelper(divisions * step, divisions, 0xc5c9d0, 0xdfe2e6);
  grid.rotateX(Math.PI / 2);
  const centre = box.getCenter(new THREE.Vector3());
  grid.position.set(Math.round(centre.x / step) * step, Math.round(centre.y / step) * step,
                    box.min.z - 0.25 * Math.max(extent.z, 0.3 * reach));
  grid.userData.role = 'grid';
  scene.add(grid);

  // --- the end-effector's path of the current run: approach and reconfiguration apart -----------
  let pathObjects = [];
  function tube(points, colour, role) {
    if (points.length < 2) return null;
    const curve = new THREE.CatmullRomCurve3(points, false, 'centripetal');
    const g = new THREE.TubeGeometry(curve, Math.min(2000, 3 * points.length), 0.55 * lineRadius, 10, false);
    const m = new THREE.Mesh(g, material(colour, { roughness: 0.5 }));
    m.userData.role = role;
    m.userData.points = points.length;
    scene.add(m);
    return m;
  }
  function buildPath(r) {
    for (const o of pathObjects) {
      scene.remove(o);
      o.geometry.dispose();
    }
    const pts = [];
    for (let k = 0; k < r.t.length; ++k) pts.push(v3(r.ee, 3 * k));
    const split = r.approach_begin;  // first sample of the approach (0: no reconfiguration)
    const c = r.capture_index;
    pathObjects = [];
    const re = split > 0 ? tube(pts.slice(0, split + 1), COLOURS.reconfiguration, 'path-reconfiguration') : null;
    const ap = tube(pts.slice(split, c + 1), COLOURS[r.name] || 0x444444, 'path-approach');
    const post = hasPost(r) ? tube(pts.slice(c), COLOURS.detumble, 'path-detumble') : null;
    for (const o of [re, ap, post]) if (o) pathObjects.push(o);
  }

  // --- camera ---------------------------------------------------------------------------------------
  const controls = new OrbitControls(camera, renderer.domElement);
  function frameScene() {
    const radius = 0.5 * Math.max(extent.length(), 0.5);
    const fov = (camera.fov * Math.PI) / 180;
    const dist = (0.9 * radius) / Math.sin(Math.min(fov, fov * camera.aspect) / 2);
    const dir = new THREE.Vector3(0.45, -1.0, 0.8).normalize();
    camera.position.copy(centre).addScaledVector(dir, dist);
    camera.near = dist / 100;
    camera.far = dist * 20;
    camera.updateProjectionMatrix();
    controls.target.copy(centre);
    controls.update();
    sun.position.copy(centre).add(new THREE.Vector3(0.5, -0.6, 1).multiplyScalar(2 * radius));
  }
  frameScene();

  // --- posing at a time -----------------------------------------------------------------------------
  const tmpA = new THREE.Vector3(), tmpB = new THREE.Vector3(), qa = new THREE.Quaternion(), qb = new THREE.Quaternion();
  const zAxis = new THREE.Vector3(0, 0, 1);
  // pose obj from array a at frames k and k+1 blended by s (positions linear, attitudes slerp)
  function blend(obj, a, i, j, s) {
    tmpA.set(a[i], a[i + 1], a[i + 2]);
    tmpB.set(a[j], a[j + 1], a[j + 2]);
    obj.position.lerpVectors(tmpA, tmpB, s);
    qa.set(a[i + 4], a[i + 5], a[i + 6], a[i + 3]);
    qb.set(a[j + 4], a[j + 5], a[j + 6], a[j + 3]);
    obj.quaternion.slerpQuaternions(qa, qb, s);
  }
  let run = runs[0];
  let time = 0;
  function frameAt(r, t) {  // k, s with t between r.t[k] and r.t[k + 1]
    const ts = r.t;
    if (t <= ts[0]) return [0, 0];
    const n = ts.length;
    if (t >= ts[n - 1]) return [n - 1, 0];
    let lo = 0, hi = n - 1;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (ts[mid] <= t) lo = mid; else hi = mid;
    }
    return [lo, (t - ts[lo]) / (ts[hi] - ts[lo])];
  }
  const eePoint = v3(data.end_effector_point);
  function setTime(t) {
    time = Math.min(Math.max(t, run.t[0]), endTime(run));
    const [k, s] = frameAt(run, time);
    const k1 = Math.min(k + 1, run.t.length - 1);
    for (let b = 0; b < nb; ++b) {
      const [a, i] = bodyPose(run, b, k);
      const [, j] = bodyPose(run, b, k1);
      blend(bodyGroups[b], a, i, j, s);
    }
    blend(targetGroup, run.target, 7 * k, 7 * k1, s);
    const eeWorld = eePoint.clone().applyQuaternion(bodyGroups[data.end_effector_body].quaternion)
      .add(bodyGroups[data.end_effector_body].position);
    eeMarker.position.copy(eeWorld);
    for (const seg of segments) {
      const p = bodyGroups[seg.from].position;
      const q = seg.to === 'ee' ? eeWorld : bodyGroups[seg.to].position;
      const d = tmpA.subVectors(q, p);
      const L = d.length();
      seg.mesh.position.copy(p);
      seg.mesh.scale.set(lineRadius, lineRadius, Math.max(L, 1e-9));
      if (L > 0) seg.mesh.quaternion.setFromUnitVectors(zAxis, d.multiplyScalar(1 / L));
    }
    updateReadout(k, s);
  }

  // --- the controls on the page ----------------------------------------------------------------------
  const slider = $('time'), playButton = $('play'), speedSelect = $('speed');
  const fmt = (x, d) => Number(x).toFixed(d);
  function updateReadout(k, s) {
    const r = run;
    const k1 = Math.min(k + 1, r.t.length - 1);
    const mie = r.mie[k] + s * (r.mie[k1] - r.mie[k]);
    const f = r.fmax[k] + s * (r.fmax[k1] - r.fmax[k]);
    const T = captureTime(r), end = endTime(r);
    const after = hasPost(r) && time > T + 1e-9;
    const captured = !after && time >= T - 1e-9;
    const phase = r.approach_begin > 0 && k < r.approach_begin ? 'reconfiguration' : 'approach';
    $('clock').textContent = `t = ${fmt(time, 1)} s of ${fmt(end, 1)} s`;
    const ph = $('phase');
    ph.textContent = after ? 'after the capture' : captured ? 'capture' : phase;
    ph.className = 'badge ' + (after ? 'post-capture' : captured ? 'capture' : phase);
    $('mie').textContent = fmt(mie, 3);
    $('fmax').textContent = fmt(f / 1000, 3);
    for (const id of ['grip-row', 'grip-key', 'jrate-row', 'jrate-key']) $(id).style.display = after ? '' : 'none';
    if (after) {
      $('grip').textContent = fmt(r.grip[k] + s * (r.grip[k1] - r.grip[k]), 2);
      $('jrate').textContent = fmt(r.jrate[k] + s * (r.jrate[k1] - r.jrate[k]), 3);
    }
    slider.value = String(time);
  }
  function selectRun(name) {
    run = runs.find((r) => r.name === name) || runs[0];
    buildPath(run);
    const T = endTime(run);
    slider.min = String(run.t[0]);
    slider.max = String(T);
    slider.step = String((T - run.t[0]) / 2000);
    // the slider's marks: the end of the reconfiguration, the capture
    const marks = $('marks');
    marks.innerHTML = '';
    const mark = (t, cls, label) => {
      const m = document.createElement('div');
      m.className = 'mark ' + cls;
      m.style.left = `${(100 * (t - run.t[0])) / (T - run.t[0])}%`;
      m.title = label;
      marks.appendChild(m);
    };
    if (run.approach_begin > 0) mark(run.t[run.approach_begin], 'reconfiguration', 'end of the reconfiguration');
    mark(captureTime(run), 'capture', 'capture');
    if (hasPost(run)) mark(T, 'rest', 'at rest');
    for (const b of document.querySelectorAll('#runs button')) b.classList.toggle('on', b.dataset.run === run.name);
    $('legend-approach').style.background = hex(COLOURS[run.name] || 0x444444);
    $('legend-reconfiguration-row').style.display = run.approach_begin > 0 ? '' : 'none';
    $('legend-detumble-row').style.display = hasPost(run) ? '' : 'none';
    setTime(Math.min(time, T));
  }

  // run buttons: name, M_ie and F_max of each run
  const runBox = $('runs');
  for (const r of runs) {
    const b = document.createElement('button');
    b.dataset.run = r.name;
    b.innerHTML = `<span class="swatch" style="background:${hex(COLOURS[r.name] || 0x777777)}"></span>` +
      `<b>${r.label}</b><span class="num">M_ie ${fmt(r.integrated_effective_mass, 3)} kg · F_max ` +
      `${fmt(r.f_max_closed_form / 1000, 3)} kN${r.reconfigured ? '<br>reconfigured first' : ''}</span>`;
    b.addEventListener('click', () => selectRun(r.name));
    runBox.appendChild(b);
  }
  $('legend-target').style.background = hex(COLOURS.target);
  $('legend-normal').style.background = hex(COLOURS.normal);
  $('legend-reconfiguration').style.background = hex(COLOURS.reconfiguration);
  $('legend-detumble').style.background = hex(COLOURS.detumble);
  $('legend-bus').style.background = hex(COLOURS.bus);
  $('legend-links').style.background = hex(COLOURS.link);

  let playing = false, last = 0;
  const playSeconds = () => Number(speedSelect.value);  // a whole run in this many seconds (0: real time)
  function setPlaying(p) {
    playing = p;
    playButton.textContent = p ? '❚❚' : '▶';
    playButton.title = p ? 'pause' : 'play';
    last = performance.now();
    if (p && time >= endTime(run) - 1e-9) setTime(run.t[0]);
  }
  playButton.addEventListener('click', () => setPlaying(!playing));
  slider.addEventListener('input', () => {
    setPlaying(false);
    setTime(Number(slider.value));
  });
  window.addEventListener('keydown', (e) => {
    if (e.code === 'Space' && e.target === document.body) {
      e.preventDefault();
      setPlaying(!playing);
    }
  });

  function resize() {
    const w = canvasBox.clientWidth, h = canvasBox.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  window.addEventListener('resize', resize);

  function loop(now) {
    if (playing) {
      // the approach in the chosen time, the post-capture run (seconds, not minutes) in half of it
      const T = captureTime(run), end = endTime(run), t0 = run.t[0];
      const after = time >= T - 1e-9 && end > T;
      const rate = playSeconds() > 0 ? (after ? (end - T) / (0.5 * playSeconds()) : (T - t0) / playSeconds()) : 1;
      const t = time + ((now - last) / 1000) * rate;
      last = now;
      setTime(t);
      if (t >= end) setPlaying(false);
    }
    controls.update();
    renderer.render(scene, camera);
    requestAnimationFrame(loop);
  }

  // --- start: the run and the time of the page's address (#run=global&t=12.5), else the data's
  // first run at its capture instant -----------------------------------------------------------
  const hash = new URLSearchParams(window.location.hash.slice(1));
  selectRun(hash.get('run') || data.initial_run);
  const t0 = Number(hash.get('t'));
  setTime(hash.has('t') && Number.isFinite(t0) ? t0 : captureTime(run));
  renderer.render(scene, camera);
  requestAnimationFrame(loop);

  // --- what the page shows, for tests and scripts: the scene's objects by role -------------------
  const roles = {};
  scene.traverse((o) => {
    const role = o.userData.role;
    if (role && role !== 'edges') roles[role] = (roles[role] || 0) + 1;
  });
  const gl = renderer.getContext();
  return {
    roles,
    target_kind: tshape.kind,
    target_schematic: !!tshape.schematic,
    shapes: hasShapes,
    path_points: Object.fromEntries(pathObjects.map((o) => [o.userData.role, o.userData.points])),
    runs: runs.map((r) => r.name),
    run: run.name,
    frames: run.t.length,
    time,
    capture_time: captureTime(run),
    end_time: endTime(run),
    post_capture: runs.filter(hasPost).map((r) => r.name),
    phase: $('phase').textContent,
    target_pose: [targetGroup.position.x, targetGroup.position.y, targetGroup.position.z, targetGroup.quaternion.w,
                  targetGroup.quaternion.x, targetGroup.quaternion.y, targetGroup.quaternion.z],
    webgl: gl.getParameter(gl.VERSION),
  };
};
