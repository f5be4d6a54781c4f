// The replay viewer: reads the page's data block, builds the scene (cairn's
// bodies solid, Bullet's as orange wireframes when the replay has them),
// an orbit camera (drag to turn, right-drag or shift-drag to pan, wheel to
// zoom) that can follow the picked body, and renders on every animation
// frame. window.cairnViewer is the handle the browser tests drive
// (tests/browser/viewer_test.py).
'use strict';
var CairnViewer = CairnViewer || {};

(function (V) {
  const STATIC = new THREE.Color(0x8a8f98), KINEMATIC = new THREE.Color(0x6f8fbf);
  const ASLEEP = new THREE.Color(0x505357), PICKED = new THREE.Color(0xffd84d);
  const colour = new THREE.Color();

  function hue(i, s, l) { return colour.setHSL((i * 0.618034) % 1, s, l); }

  // Average body size and weight (for overlay lengths) and the center and
  // radius of the moving bodies at the start (for the camera and the
  // planes); static bodies count only in a scene without moving ones (a
  // ground box would dwarf the stack on it).
  function measure(replay) {
    const box = new THREE.Box3(), p = new THREE.Vector3();
    const moving = replay.bodies.some((b) => b.type !== 'static');
    let size = 0, sized = 0, weight = 0, heavy = 0;
    replay.bodies.forEach((body, b) => {
      let s = 0;
      for (const shape of body.shapes) s = Math.max(s, V.shapeSize(shape));
      if (s === 0) return;  // planes only
      if (body.type !== 'static') { size += s; sized++; }
      if (body.type === 'dynamic') { weight += body.mass * Math.hypot(...replay.gravity); heavy++; }
      if (moving && body.type === 'static') return;
      p.fromArray(replay.cairn.position, 3 * b);
      box.expandByPoint(p.clone().addScalar(-s / 2));
      box.expandByPoint(p.clone().addScalar(s / 2));
    });
    if (box.isEmpty()) box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    return {
      center: sphere.center, radius: Math.max(sphere.radius, 0.5),
      size: sized ? size / sized : 1, weight: heavy && weight > 0 ? weight / heavy : 1,
    };
  }

  function Viewer() {
    const replay = V.loadReplay(document.getElementById('cairn-replay').textContent);
    this.replay = replay;
    const m = measure(replay);
    this.renderer = new THREE.WebGLRenderer({ antialias: replay.shapeCount < 300 });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(0x20242a);
    // The shape batches keep their poses in a float texture (shapes.js).
    if (!this.renderer.capabilities.floatVertexTextures)
      throw new Error('this browser\'s WebGL cannot read float textures in vertex shaders, which the viewer draws with');
    document.getElementById('view').appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x404048, 0.65));
    const sun = new THREE.DirectionalLight(0xffffff, 0.6);
    sun.position.set(0.5, 1, 0.8);
    this.scene.add(sun);

    this.camera = new THREE.PerspectiveCamera(45, 1, m.radius / 100, m.radius * 100);
    const dir = new THREE.Vector3(0.45, 0.4, 1.0).normalize();
    this.camera.position.copy(m.center).addScaledVector(dir, 2.6 * m.radius);
    this.controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.copy(m.center);
    this.controls.update();

    const planeSize = Math.max(20, 8 * m.radius);
    this.shapes = new V.ShapeLayer(replay, { bodies: () => true, planeSize });
    for (const mesh of this.shapes.meshes) this.scene.add(mesh);
    if (replay.bullet) {
      this.bullet = new V.ShapeLayer(replay, { wireframe: true, color: 0xff9933, planeSize,
        bodies: (b) => replay.bodies[b].type !== 'static' });
      for (const mesh of this.bullet.meshes) this.scene.add(mesh);
    }
    this.overlays = new V.Overlays(replay, m);
    this.scene.add(this.overlays.group);
    this.timeline = new V.Timeline(replay);
    this.picking = new V.Picking(this);
    this.show = { sleep: false, islands: false, bullet: !!replay.bullet };
    this.follow = document.getElementById('follow');
    this.followFrom = null;
    this.shownFrame = -1;
    this.frameTimes = this.scriptTimes = null;

    this.setupHud();
    window.addEventListener('resize', () => this.resize());
    this.resize();
    this.repaint();
  }

  Viewer.prototype.setupHud = function () {
    const r = this.replay;
    document.getElementById('title').textContent = r.title + ': ' + r.bodyCount + ' bodies, ' + r.shapeCount +
      ' shapes, ' + r.frames + ' frames';
    document.getElementById('source').textContent = r.source;
    const notes = document.getElementById('notes');
    for (const n of r.notes) { const li = document.createElement('li'); li.textContent = n; notes.appendChild(li); }
    for (const box of document.querySelectorAll('[data-overlay]')) {
      const name = box.dataset.overlay;
      const available = name === 'bullet' ? !!r.bullet : name === 'velocities' ? !!r.cairn.velocity : !!r.overlays;
      if (!available) {
        box.checked = false;
        box.disabled = true;
        box.parentElement.classList.add('unavailable');
        box.parentElement.title = name === 'bullet' ? 'only in the pages of cairn validate and cairn sweep'
          : 'recorded only while cairn runs the scene (cairn view SCENE --run)';
      }
      box.onchange = () => this.setOverlay(name, box.checked);
    }
    this.follow.onchange = () => { this.followFrom = null; };
  };

  Viewer.prototype.setOverlay = function (name, on) {
    const box = document.querySelector('[data-overlay="' + name + '"]');
    if (box && !box.disabled) box.checked = on;
    if (name === 'sleep' || name === 'islands') this.show[name] = on;
    else if (name === 'bullet') { this.show.bullet = on; if (this.bullet) this.bullet.setVisible(on); }
    else this.overlays.show(name, on);
    this.shownFrame = -1;  // redraw
    this.repaint();
  };

  Viewer.prototype.colorOf = function (b) {
    const r = this.replay, body = r.bodies[b], f = this.timeline.frame(), k = f * r.bodyCount + b;
    if (b === this.picking.body) return PICKED;
    if (body.type === 'static') return STATIC;
    if (r.overlays && this.show.sleep && r.overlays.asleep[k]) return ASLEEP;
    if (r.overlays && this.show.islands && r.overlays.island[k] >= 0) return hue(r.overlays.island[k], 0.75, 0.5);
    if (body.type === 'kinematic') return KINEMATIC;
    return hue(b, 0.45, 0.58);
  };

  Viewer.prototype.repaint = function () { this.shapes.paint((b) => this.colorOf(b)); };

  Viewer.prototype.resize = function () {
    const w = window.innerWidth, h = window.innerHeight;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  };

  // Moves the camera with the picked body, keeping the view direction.
  Viewer.prototype.followBody = function (f) {
    const b = this.picking.body;
    if (!this.follow.checked || b < 0) { this.followFrom = null; return; }
    const p = new THREE.Vector3().fromArray(this.replay.cairn.position, 3 * (f * this.replay.bodyCount + b));
    if (this.followFrom) {
      const d = p.clone().sub(this.followFrom);
      this.camera.position.add(d);
      this.controls.target.add(d);
    } else {
      this.camera.position.add(p.clone().sub(this.controls.target));
      this.controls.target.copy(p);
    }
    this.followFrom = p;
  };

  Viewer.prototype.readout = function (f) {
    const r = this.replay, o = r.overlays;
    let text = '';
    if (o) {
      const shown = o.contactFrame[f], n = o.pointBegin[shown + 1] - o.pointBegin[shown];
      let asleep = 0;
      for (let b = 0; b < r.bodyCount; b++) asleep += o.asleep[f * r.bodyCount + b];
      text += n + ' contact points, ' + asleep + ' bodies asleep\n';
      const j = this.overlays.worstJoint(f);
      if (j) text += 'largest joint error: ' + j.linear.toExponential(2) + ' m, ' + j.angular.toExponential(2) +
        ' rad (\'' + j.name + '\')\n';
    }
    if (r.bullet) {
      text += 'cairn solid, Bullet orange wireframe\n';
      const p = r.parting;
      text += p && p.frame >= 0 ? 'they part by more than ' + p.tolerance + ' m at t = ' + p.time.toFixed(3) +
        ' s (\'' + r.bodies[p.body].name + '\'; red mark)' : 'within ' + (p ? p.tolerance : '?') + ' m of each other throughout';
    }
    document.getElementById('readout').textContent = text;
  };

  Viewer.prototype.draw = function (f) {
    const r = this.replay;
    if (f !== this.shownFrame) {
      this.shapes.update(r.cairn, f, r.bodyCount);
      if (this.bullet) this.bullet.update(r.bullet, Math.min(f, r.bullet.time.length - 1), r.bodyCount);
      this.overlays.update(f);
      if (this.show.sleep || this.show.islands) this.repaint();
      this.readout(f);
      this.shownFrame = f;
    }
    this.picking.update(f);
    this.followBody(f);
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
  };

  Viewer.prototype.start = function () {
    let last = performance.now();
    const loop = (now) => {
      const begin = performance.now();  // `now` is the frame's start, earlier when the thread is busy
      const seconds = Math.min(0.1, (now - last) / 1000);
      if (this.frameTimes) this.frameTimes.push(now - last);
      last = now;
      this.draw(this.timeline.advance(seconds));
      if (this.scriptTimes) this.scriptTimes.push(performance.now() - begin);
      requestAnimationFrame(loop);
    };
    this.draw(this.timeline.advance(0));
    requestAnimationFrame(loop);
  };

  // The handle for tests and for the console.
  function api(viewer) {
    const r = viewer.replay, t = viewer.timeline;
    const bodyIndex = (name) => r.bodies.findIndex((b) => b.name === name);
    return {
      ready: true,
      viewer,  // the objects themselves, for the console
      loadMilliseconds: performance.now(),
      shapeCount: r.shapeCount,
      frames: r.frames,
      drawnInstances: () => viewer.shapes.drawnInstances(),
      bulletInstances: () => (viewer.bullet ? viewer.bullet.drawnInstances() : 0),
      instancesByKind: () => viewer.shapes.instancesByKind(),
      play: () => t.setPlaying(true),
      pause: () => t.setPlaying(false),
      seek: (seconds) => { t.seek(seconds); viewer.draw(t.advance(0)); return t.frame(); },
      frame: () => t.frame(),
      time: () => r.cairn.time[t.frame()],
      setOverlay: (name, on) => viewer.setOverlay(name, on),
      bodyPosition: (name) => V.vec3(r.cairn.position, t.frame() * r.bodyCount + bodyIndex(name)),
      // Where a body's center of mass is on the screen (CSS pixels).
      screenPoint: (name) => {
        const p = new THREE.Vector3().fromArray(r.cairn.position, 3 * (t.frame() * r.bodyCount + bodyIndex(name)));
        p.project(viewer.camera);
        const rect = viewer.renderer.domElement.getBoundingClientRect();
        return { x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height };
      },
      pickedName: () => (viewer.picking.body >= 0 ? r.bodies[viewer.picking.body].name : null),
      infoText: () => document.getElementById('info').textContent,
      parting: () => r.parting,
      // Plays for `ms` and reports the intervals between animation frames
      // and the time the page's script spends in each (advancing, updating
      // the instances and overlays, issuing the draw; the rendering itself
      // runs in the GPU process).
      measureFrames: (ms) => new Promise((resolve) => {
        viewer.frameTimes = [];
        viewer.scriptTimes = [];
        t.setPlaying(true);
        setTimeout(() => {
          const d = viewer.frameTimes.slice(1).sort((a, b) => a - b), s = viewer.scriptTimes;
          viewer.frameTimes = viewer.scriptTimes = null;
          const mean = d.reduce((a, x) => a + x, 0) / Math.max(1, d.length);
          resolve({ frames: d.length, meanMs: mean, p95Ms: d[Math.floor(0.95 * (d.length - 1))] || 0,
                    fps: mean > 0 ? 1000 / mean : 0, scriptMs: s.reduce((a, x) => a + x, 0) / Math.max(1, s.length) });
        }, ms);
      }),
    };
  }

  const viewer = new Viewer();
  viewer.start();
  viewer.timeline.setPlaying(!/paused/.test(location.hash));
  window.cairnViewer = api(viewer);
})(CairnViewer);
