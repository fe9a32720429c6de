// The mechsys viewer page: reads the JSON block the Python side wrote (python/mechsys/viewer),
// builds the three.js scene, the timeline and the uPlot plots, and keeps them on one time.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { decode } from './data.js';
import { buildPlots } from './plots.js';

const PALETTE = [0x4f7cc3, 0xd9822b, 0x3d9970, 0xb0413e, 0x7d5ba6, 0x8c6d46, 0xc9609b, 0x5f6b7a, 0xa6a63c, 0x2aa1b3];
const STATE_COLORS = [0x9aa0a6, 0x2f6fd6, 0xe8871e]; // open, stick, slip
const SPEEDS = [0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10];

function main() {
  const data = JSON.parse(document.getElementById('mechsys-data').textContent);
  const t = decode(data.t);
  const pose = decode(data.pose); // frames x bodies x 7 (p, q wxyz)
  const nb = data.bodies.length;
  const nf = data.frames;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf6f7f9);
  const host = document.getElementById('scene');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  host.appendChild(renderer.domElement);

  // the up direction: against gravity, +y for planar models, else +z
  const g = new THREE.Vector3(...data.gravity);
  const up = data.planar ? new THREE.Vector3(0, 1, 0)
    : (g.lengthSq() > 0 ? g.clone().negate().normalize() : new THREE.Vector3(0, 0, 1));
  const L = data.scene;
  const camera = new THREE.PerspectiveCamera(40, 1, L * 1e-3, L * 200);
  camera.up.copy(up);

  scene.add(new THREE.HemisphereLight(0xffffff, 0x8d8d8d, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  scene.add(sun);

  const unit = data.scene * 0.015;
  const bodies = data.bodies.map((b, k) => makeBody(b, PALETTE[k % PALETTE.length], unit));
  bodies.forEach((o) => scene.add(o.group));
  const ground = makeBody(data.ground, 0xb9bec6, unit);
  scene.add(ground.group);
  const triads = [...bodies, ground].flatMap((o) => o.triads);

  // elastic bodies: their node lines, deformed (magnified) with the frames
  const elastic = (data.elastic || []).map((e) => {
    const nodes = decode(e.nodes), disp = decode(e.disp);
    const n = nodes.length / 3;
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(nodes), 3));
    const group = bodies[e.body].group;
    const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: PALETTE[e.body % PALETTE.length] }));
    const dots = new THREE.Points(geo, new THREE.PointsMaterial({ color: PALETTE[e.body % PALETTE.length], size: unit * 0.8 }));
    line.frustumCulled = false;
    dots.frustumCulled = false;
    group.add(line, dots);
    return {
      scale: e.scale,
      geo,
      update(f) {
        const p = geo.attributes.position.array;
        for (let k = 0; k < 3 * n; k++) p[k] = nodes[k] + e.scale * disp[f * 3 * n + k];
        geo.attributes.position.needsUpdate = true;
      },
    };
  });
  const contacts = data.contacts.map((c) => makeContact(c, unit));
  contacts.forEach((c) => scene.add(c.group));
  const trails = data.trails.map((tr, k) => {
    const path = decode(tr.path);
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(path, 3));
    const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: PALETTE[(k + 3) % PALETTE.length] }));
    line.frustumCulled = false;
    scene.add(line);
    return line;
  });

  // events: impacts flash at their contact point
  const ev = { t: decode(data.events.t), contact: decode(data.events.contact), kind: decode(data.events.kind) };
  const impactKind = data.events.kinds.indexOf('impact');
  const flashes = [];
  const flashGeo = new THREE.SphereGeometry(unit * 2.5, 16, 12);

  // camera: look at the whole motion (the bodies' origins over the run, and their shapes at the start)
  const box = new THREE.Box3();
  box.expandByPoint(new THREE.Vector3(...data.bounds[0])).expandByPoint(new THREE.Vector3(...data.bounds[1]));
  for (let b = 0; b < nb; b++) {
    const o = b * 7;
    bodies[b].group.position.set(pose[o], pose[o + 1], pose[o + 2]);
    bodies[b].group.quaternion.set(pose[o + 4], pose[o + 5], pose[o + 6], pose[o + 3]);
    box.expandByObject(bodies[b].group);
  }
  trails.forEach((line) => { line.geometry.computeBoundingBox(); box.union(line.geometry.boundingBox); });
  if (box.isEmpty()) box.setFromCenterAndSize(new THREE.Vector3(), new THREE.Vector3(L, L, L));
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() * 0.6, L * 0.3);
  const view = data.planar ? new THREE.Vector3(0, 0, 1)
    : new THREE.Vector3(1, -1.6, 0.9).normalize().applyQuaternion(new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 0, 1), up));
  camera.position.copy(center).addScaledVector(view, radius / Math.tan((camera.fov * Math.PI) / 360));
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(center);
  controls.update();
  sun.position.copy(center).addScaledVector(up, 3 * radius).addScaledVector(view, radius);

  // ---- time ------------------------------------------------------------------------------------
  const state = { frame: 0, time: t[0], playing: false, speed: 1, follow: data.follow, last: null };
  const duration = t[nf - 1] - t[0];
  state.speed = duration >= 1 && duration <= 30 ? 1
    : SPEEDS.reduce((best, s) => (Math.abs(Math.log(s / (duration / 8 || 1))) < Math.abs(Math.log(best / (duration / 8 || 1))) ? s : best), 1);
  const scrub = document.getElementById('scrub');
  scrub.max = String(nf - 1);
  const speedSel = document.getElementById('speed');
  for (const s of SPEEDS) speedSel.add(new Option(`×${s}`, String(s), false, s === state.speed));
  const followSel = document.getElementById('follow');
  data.bodies.forEach((b) => followSel.add(new Option(b.name, b.name, false, b.name === data.follow)));
  const timeLabel = document.getElementById('time');
  const magnified = elastic.filter((e) => e.scale !== 1).map((e) => e.scale);
  document.getElementById('info').textContent =
    `${nb} bodies · ${data.contacts.length} contact points · ${nf} of ${data.recorded} frames · ${fmt(duration)} s`
    + (magnified.length ? ` · elastic deflection ×${Math.max(...magnified)}` : '');
  const legend = document.getElementById('legend');
  legend.style.display = data.contacts.length ? '' : 'none';
  legend.innerHTML = data.contacts.length
    ? '<i style="background:#2f6fd6"></i>stick<i style="background:#e8871e"></i>slip<i style="background:#9aa0a6"></i>open' : '';

  const plots = buildPlots(document.getElementById('plots'), data.plots, (time) => setTime(time, true));

  function frameAt(time) {
    let lo = 0, hi = nf - 1;
    if (time <= t[0]) return 0;
    if (time >= t[hi]) return hi;
    while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (t[mid] <= time) lo = mid; else hi = mid; }
    return time - t[lo] < t[hi] - time ? lo : hi;
  }

  const tmp = new THREE.Vector3();
  function applyFrame(f, prevTime) {
    const base = f * nb * 7;
    const before = state.follow ? bodies[data.bodies.findIndex((b) => b.name === state.follow)]?.group.position.clone() : null;
    for (let b = 0; b < nb; b++) {
      const o = base + b * 7;
      bodies[b].group.position.set(pose[o], pose[o + 1], pose[o + 2]);
      bodies[b].group.quaternion.set(pose[o + 4], pose[o + 5], pose[o + 6], pose[o + 3]);
    }
    elastic.forEach((e) => e.update(f));
    const showContacts = document.getElementById('show-contacts').checked;
    contacts.forEach((c) => c.update(f, showContacts));
    trails.forEach((line) => line.geometry.setDrawRange(0, f + 1));
    if (before) {
      const target = bodies[data.bodies.findIndex((b) => b.name === state.follow)].group.position;
      tmp.subVectors(target, before);
      camera.position.add(tmp);
      controls.target.add(tmp);
    }
    // impacts between the previous time and now flash
    if (impactKind >= 0 && prevTime !== null && t[f] > prevTime) {
      for (let k = 0; k < ev.t.length; k++) {
        if (ev.kind[k] === impactKind && ev.t[k] > prevTime && ev.t[k] <= t[f] && ev.contact[k] >= 0) {
          const c = contacts.find((x) => x.contact === data.contacts[ev.contact[k]].contact);
          if (c) flash(c.dot.position);
        }
      }
    }
    state.frame = f;
    scrub.value = String(f);
    timeLabel.textContent = `t = ${fmt(t[f])} s`;
    plots.forEach((p) => p.cursor(t[f]));
  }

  function flash(at) {
    const m = new THREE.Mesh(flashGeo, new THREE.MeshBasicMaterial({ color: 0xffd400, transparent: true, opacity: 0.9 }));
    m.position.copy(at);
    scene.add(m);
    flashes.push({ mesh: m, born: performance.now() });
  }

  function setTime(time, fromUser) {
    const prev = state.time;
    state.time = Math.min(Math.max(time, t[0]), t[nf - 1]);
    applyFrame(frameAt(state.time), fromUser ? null : prev);
  }
  function setFrame(f) {
    f = Math.min(Math.max(Math.round(f), 0), nf - 1);
    state.time = t[f];
    applyFrame(f, null);
  }

  const playBtn = document.getElementById('play');
  function setPlaying(on) {
    state.playing = on;
    state.last = null;
    playBtn.innerHTML = on ? '&#10074;&#10074;' : '&#9654;';
    if (on && state.frame >= nf - 1) setFrame(0);
  }
  playBtn.addEventListener('click', () => setPlaying(!state.playing));
  document.getElementById('prev').addEventListener('click', () => { setPlaying(false); setFrame(state.frame - 1); });
  document.getElementById('next').addEventListener('click', () => { setPlaying(false); setFrame(state.frame + 1); });
  scrub.addEventListener('input', () => { setPlaying(false); setFrame(Number(scrub.value)); });
  speedSel.addEventListener('change', () => { state.speed = Number(speedSel.value); });
  followSel.addEventListener('change', () => { state.follow = followSel.value || null; });
  document.getElementById('show-frames').addEventListener('change', (e) => triads.forEach((x) => { x.visible = e.target.checked; }));
  document.getElementById('show-trails').addEventListener('change', (e) => trails.forEach((x) => { x.visible = e.target.checked; }));
  document.getElementById('show-contacts').addEventListener('change', () => applyFrame(state.frame, null));
  window.addEventListener('keydown', (e) => {
    if (e.target instanceof HTMLInputElement && e.target.type !== 'range') return;
    if (e.key === ' ') { setPlaying(!state.playing); e.preventDefault(); }
    if (e.key === 'ArrowRight') { setPlaying(false); setFrame(state.frame + 1); }
    if (e.key === 'ArrowLeft') { setPlaying(false); setFrame(state.frame - 1); }
  });

  function resize() {
    const w = host.clientWidth, h = host.clientHeight;
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  }
  window.addEventListener('resize', resize);
  resize();
  setFrame(0);

  function loop(now) {
    if (state.playing) {
      if (state.last !== null) {
        const next = state.time + ((now - state.last) / 1000) * state.speed;
        if (next >= t[nf - 1]) { setTime(t[nf - 1], false); setPlaying(false); } else setTime(next, false);
      }
      state.last = now;
    }
    for (let k = flashes.length - 1; k >= 0; k--) {
      const age = (now - flashes[k].born) / 400;
      if (age >= 1) { scene.remove(flashes[k].mesh); flashes[k].mesh.material.dispose(); flashes.splice(k, 1); continue; }
      flashes[k].mesh.material.opacity = 0.9 * (1 - age);
      flashes[k].mesh.scale.setScalar(1 + age);
    }
    controls.update();
    renderer.render(scene, camera);
    requestAnimationFrame(loop);
  }
  requestAnimationFrame(loop);

  // what the browser tests read and drive
  window.mechsys = {
    ready: true,
    bodyCount: bodies.length,
    bodyNames: data.bodies.map((b) => b.name),
    frames: nf,
    contactCount: contacts.length,
    setFrame, setTime,
    frame: () => state.frame,
    time: () => t[state.frame],
    play: () => setPlaying(true),
    bodyPosition: (name) => bodies[data.bodies.findIndex((b) => b.name === name)].group.position.toArray(),
    bodyQuaternion: (name) => { const q = bodies[data.bodies.findIndex((b) => b.name === name)].group.quaternion; return [q.w, q.x, q.y, q.z]; },
    contactVisible: (k) => contacts[k].dot.visible,
    contactColor: (k) => contacts[k].dot.material.color.getHex(),
    plotCount: plots.length,
    // the body groups actually in the scene (not the data's list)
    sceneBodyCount: () => scene.children.filter((o) => o.isGroup && o.name !== 'ground' && bodies.some((b) => b.group === o)).length,
    triadsVisible: () => triads.length > 0 && triads.every((x) => x.visible),
    cameraTarget: () => controls.target.toArray(),
    // as playback does, from the current time: impacts passed on the way flash
    advanceTo: (time) => setTime(time, false),
    flashCount: () => flashes.length,
    // node positions of elastic body k's line (body frame, magnified as drawn)
    elasticNodes: (k) => Array.from(elastic[k].geo.attributes.position.array),
    elasticScale: (k) => elastic[k].scale,
  };
}

function fmt(x) {
  return Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(3) : x.toFixed(4);
}

function makeBody(b, color, unit) {
  const group = new THREE.Group();
  group.name = b.name;
  for (const p of b.parts) {
    const v = decode(p.v);
    const c = p.color ? new THREE.Color(...p.color) : new THREE.Color(p.ground ? 0xc9ced6 : color);
    if (p.kind === 'mesh') {
      let geo = new THREE.BufferGeometry();
      geo.setAttribute('position', new THREE.BufferAttribute(v, 3));
      geo.setIndex(new THREE.BufferAttribute(decode(p.f), 1));
      // few vertices (a box, a plane): flat faces; many: smooth
      if (v.length / 3 < 40) geo = geo.toNonIndexed();
      geo.computeVertexNormals();
      const opacity = p.opacity ?? 1;
      const mat = new THREE.MeshStandardMaterial({
        color: c, roughness: 0.65, metalness: 0.05, side: p.side === 'double' ? THREE.DoubleSide : THREE.FrontSide,
        transparent: opacity < 1, opacity, flatShading: v.length / 3 < 40, polygonOffset: true, polygonOffsetFactor: 1,
      });
      const mesh = new THREE.Mesh(geo, mat);
      mesh.name = p.name || '';
      group.add(mesh);
    } else if (p.kind === 'line') {
      const geo = new THREE.BufferGeometry();
      geo.setAttribute('position', new THREE.BufferAttribute(v, 3));
      const Line = p.closed ? THREE.LineLoop : THREE.Line;
      group.add(new Line(geo, new THREE.LineBasicMaterial({ color: c.clone().multiplyScalar(0.6) })));
    }
  }
  const triads = (b.triads || []).map((f) => {
    const a = new THREE.AxesHelper(unit * 4);
    a.position.set(...f.p);
    a.quaternion.set(f.q[1], f.q[2], f.q[3], f.q[0]);
    a.visible = false;
    a.name = f.name;
    group.add(a);
    return a;
  });
  return { group, triads };
}

function makeContact(c, unit) {
  const point = decode(c.point), normal = decode(c.normal), friction = decode(c.friction), st = decode(c.state);
  const group = new THREE.Group();
  const dot = new THREE.Mesh(new THREE.SphereGeometry(unit * 0.8, 12, 8), new THREE.MeshBasicMaterial({ color: STATE_COLORS[0] }));
  const nArrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, STATE_COLORS[1], unit * 2, unit);
  const tArrow = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 1, 0xd6452f, unit * 2, unit);
  group.add(dot, nArrow, tArrow);
  const dir = new THREE.Vector3();
  function arrow(a, vec, o, at, color) {
    dir.set(vec[o], vec[o + 1], vec[o + 2]);
    const len = dir.length();
    if (len < unit * 0.5) { a.visible = false; return; }
    a.visible = true;
    a.position.copy(at);
    a.setDirection(dir.divideScalar(len));
    a.setLength(len, Math.min(unit * 2, len * 0.4), Math.min(unit, len * 0.2));
    if (color !== undefined) a.setColor(color);
  }
  return {
    group, dot, contact: c.contact,
    update(f, show) {
      const o = 3 * f;
      const s = st[f];
      group.visible = show;
      dot.position.set(point[o], point[o + 1], point[o + 2]);
      dot.material.color.setHex(STATE_COLORS[s] ?? STATE_COLORS[0]);
      dot.visible = s !== 0;
      if (s === 0) { nArrow.visible = false; tArrow.visible = false; return; }
      arrow(nArrow, normal, o, dot.position, STATE_COLORS[s]);
      arrow(tArrow, friction, o, dot.position);
    },
  };
}

try {
  main();
} catch (e) {
  // shown on the page and in the console: a broken page must not look like an empty scene
  document.body.insertAdjacentHTML('afterbegin', `<pre style="color:#b00;padding:8px">viewer error: ${String(e && e.stack || e)}</pre>`);
  throw e;
}
