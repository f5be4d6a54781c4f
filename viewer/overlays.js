// Overlays drawn over the bodies, each switched on and off on its own:
//   contacts    a dot at each contact point and a line along the normal
//               (from a to b) whose length is the point's normal force,
//               L = 0.5 s F / W: a point carrying the weight W of an
//               average body is half an average body size s long
//   joints      the anchor on a (green) and on b (red), the gap between
//               them, and the axis on a, coloured by the joint's error
//               from green (0) to red (5% of s or 0.1 rad)
//   velocities  a line from each moving body's center of mass to where
//               it would be 0.25 s later at its velocity
// Sleep and island colours repaint the bodies (main.js). Line buffers are
// sized once for the busiest frame and trimmed with setDrawRange.
'use strict';
var CairnViewer = CairnViewer || {};

(function (V) {
  const VELOCITY_SECONDS = 0.25;

  function lines(capacity, color) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * Math.max(1, capacity)), 3).setUsage(THREE.DynamicDrawUsage));
    g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(6 * Math.max(1, capacity)), 3).setUsage(THREE.DynamicDrawUsage));
    g.setDrawRange(0, 0);
    const m = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: THREE.VertexColors, depthTest: false }));
    m.frustumCulled = false;
    m.renderOrder = 2;
    m.userData.color = new THREE.Color(color);
    return m;
  }

  function points(capacity, size) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * Math.max(1, capacity)), 3).setUsage(THREE.DynamicDrawUsage));
    g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * Math.max(1, capacity)), 3).setUsage(THREE.DynamicDrawUsage));
    g.setDrawRange(0, 0);
    const m = new THREE.Points(g, new THREE.PointsMaterial({ size, sizeAttenuation: false, vertexColors: THREE.VertexColors, depthTest: false }));
    m.frustumCulled = false;
    m.renderOrder = 3;
    return m;
  }

  // Appends a segment or a point to a line/point set being filled.
  function Writer(object) {
    this.object = object;
    this.position = object.geometry.getAttribute('position').array;
    this.color = object.geometry.getAttribute('color').array;
    this.n = 0;  // vertices written
  }
  Writer.prototype.vertex = function (x, y, z, c) {
    const i = 3 * this.n++;
    this.position[i] = x; this.position[i + 1] = y; this.position[i + 2] = z;
    this.color[i] = c.r; this.color[i + 1] = c.g; this.color[i + 2] = c.b;
  };
  Writer.prototype.done = function () {
    const g = this.object.geometry;
    g.setDrawRange(0, this.n);
    g.getAttribute('position').needsUpdate = true;
    g.getAttribute('color').needsUpdate = true;
  };

  const CONTACT = new THREE.Color(0xffe14d), ANCHOR_A = new THREE.Color(0x4dff88), ANCHOR_B = new THREE.Color(0xff4d4d);
  const VELOCITY = new THREE.Color(0x4dd2ff), GOOD = new THREE.Color(0x4dff88), BAD = new THREE.Color(0xff3030);
  const mixed = new THREE.Color();

  // scale: { size: average body size (m), weight: average body weight (N) }
  V.Overlays = function (replay, scale) {
    this.replay = replay;
    this.scale = scale;
    this.group = new THREE.Group();
    const o = replay.overlays;
    let contacts = 0;
    if (o) for (let f = 0; f < replay.frames; f++) contacts = Math.max(contacts, o.pointBegin[f + 1] - o.pointBegin[f]);
    const joints = replay.joints.length;
    this.contactLines = lines(contacts, CONTACT);
    this.contactPoints = points(contacts, 6);
    this.jointLines = lines(2 * joints, GOOD);
    this.jointPoints = points(2 * joints, 7);
    this.velocityLines = lines(replay.bodyCount, VELOCITY);
    this.layers = {
      contacts: [this.contactLines, this.contactPoints],
      joints: [this.jointLines, this.jointPoints],
      velocities: [this.velocityLines],
    };
    for (const name in this.layers) for (const obj of this.layers[name]) { obj.visible = false; this.group.add(obj); }
  };

  V.Overlays.prototype.show = function (name, on) {
    for (const obj of this.layers[name] || []) obj.visible = on;
  };

  V.Overlays.prototype.update = function (f) {
    const r = this.replay, o = r.overlays;
    if (o && this.contactLines.visible) {
      const lw = new Writer(this.contactLines), pw = new Writer(this.contactPoints);
      const k = 0.5 * this.scale.size / this.scale.weight * r.impulseToForce;
      V.eachManifold(r, f, (m, first, count) => {
        const [nx, ny, nz] = V.vec3(o.manifoldNormal, m);
        for (let c = first; c < first + count; c++) {
          const [x, y, z] = V.vec3(o.pointPosition, c), len = k * o.pointImpulse[c];
          pw.vertex(x, y, z, CONTACT);
          lw.vertex(x, y, z, CONTACT);
          lw.vertex(x + nx * len, y + ny * len, z + nz * len, CONTACT);
        }
      });
      lw.done(); pw.done();
    }
    if (o && this.jointLines.visible) {
      const lw = new Writer(this.jointLines), pw = new Writer(this.jointPoints);
      const half = 0.4 * this.scale.size;
      for (let j = 0; j < r.joints.length; j++) {
        const k = f * r.joints.length + j;
        const [ax, ay, az] = V.vec3(o.jointAnchorA, k), [bx, by, bz] = V.vec3(o.jointAnchorB, k);
        const [ux, uy, uz] = V.vec3(o.jointAxis, k);
        const bad = Math.min(1, Math.max(o.jointError[2 * k] / (0.05 * this.scale.size), o.jointError[2 * k + 1] / 0.1));
        mixed.copy(GOOD).lerp(BAD, bad);
        lw.vertex(ax - ux * half, ay - uy * half, az - uz * half, mixed);
        lw.vertex(ax + ux * half, ay + uy * half, az + uz * half, mixed);
        lw.vertex(ax, ay, az, BAD);
        lw.vertex(bx, by, bz, BAD);
        pw.vertex(ax, ay, az, ANCHOR_A);
        pw.vertex(bx, by, bz, ANCHOR_B);
      }
      lw.done(); pw.done();
    }
    const v = r.cairn.velocity;
    if (v && this.velocityLines.visible) {
      const lw = new Writer(this.velocityLines);
      for (let b = 0; b < r.bodyCount; b++) {
        if (r.bodies[b].type === 'static') continue;
        const k = f * r.bodyCount + b;
        const [x, y, z] = V.vec3(r.cairn.position, k), [vx, vy, vz] = V.vec3(v, k);
        lw.vertex(x, y, z, VELOCITY);
        lw.vertex(x + vx * VELOCITY_SECONDS, y + vy * VELOCITY_SECONDS, z + vz * VELOCITY_SECONDS, VELOCITY);
      }
      lw.done();
    }
  };

  // The worst joint at frame f, for the readout: { name, linear, angular }.
  V.Overlays.prototype.worstJoint = function (f) {
    const r = this.replay, o = r.overlays;
    if (!o || r.joints.length === 0) return null;
    let best = null;
    for (let j = 0; j < r.joints.length; j++) {
      const k = f * r.joints.length + j, lin = o.jointError[2 * k], ang = o.jointError[2 * k + 1];
      if (!best || lin > best.linear) best = { name: r.joints[j].name || 'joint ' + j, linear: lin, angular: ang };
    }
    return best;
  };
})(CairnViewer);
