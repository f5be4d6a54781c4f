// Picking: a click (a press and release without dragging the camera) on a
// body selects it; the panel shows its name, type, mass, center of mass,
// velocities and the forces on it at the current frame:
//   gravity    m g
//   contacts   sum over its contact points of (n lambda_n + lambda_t) / h_sub,
//              lambda of the last substep (h_sub = dt / substeps), with
//              the sign of the side it is on (+ on body b, - on body a)
//   joints     each joint's constraint force on it (the World's feedback)
// and their sum. Clicking empty space clears the selection.
'use strict';
var CairnViewer = CairnViewer || {};

(function (V) {
  const raycaster = new THREE.Raycaster(), pointer = new THREE.Vector2();

  function fmt(v) { return v.map((x) => (x >= 0 ? ' ' : '') + x.toFixed(3)).join(' '); }
  function add(a, b, s) { a[0] += s * b[0]; a[1] += s * b[1]; a[2] += s * b[2]; }

  // The forces on body b at frame f: [{ label, force: [x, y, z] }].
  V.bodyForces = function (replay, b, f) {
    const body = replay.bodies[b], out = [];
    if (body.type === 'dynamic') out.push({ label: 'gravity', force: replay.gravity.map((g) => g * body.mass) });
    const o = replay.overlays;
    if (!o) return out;
    const contact = [0, 0, 0];
    let points = 0;
    V.eachManifold(replay, f, (m, first, count) => {
      const side = o.manifoldBody[2 * m + 1] === b ? 1 : o.manifoldBody[2 * m] === b ? -1 : 0;
      if (side === 0) return;
      const s = side * replay.impulseToForce;
      let normal = 0;
      for (let c = first; c < first + count; c++) normal += o.pointImpulse[c];
      add(contact, V.vec3(o.manifoldNormal, m), s * normal);
      add(contact, V.vec3(o.manifoldFriction, m), s);
      points += count;
    });
    if (points > 0) out.push({ label: 'contacts (' + points + ' points)', force: contact });
    replay.joints.forEach((j, k) => {
      const i = f * replay.joints.length + k;
      const name = 'joint \'' + (j.name || k) + '\'';
      if (j.bodies[0] === b) out.push({ label: name, force: V.vec3(o.jointForceA, i) });
      if (j.bodies[1] === b) out.push({ label: name, force: V.vec3(o.jointForceB, i) });
    });
    return out;
  };

  V.Picking = function (viewer) {
    this.viewer = viewer;
    this.body = -1;
    this.panel = document.getElementById('info');
    const canvas = viewer.renderer.domElement;
    let down = null;
    canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
    canvas.addEventListener('pointerup', (e) => {
      if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
      this.pickAt(e.clientX, e.clientY);
    });
  };

  V.Picking.prototype.pickAt = function (x, y) {
    const rect = this.viewer.renderer.domElement.getBoundingClientRect();
    pointer.set(((x - rect.left) / rect.width) * 2 - 1, -((y - rect.top) / rect.height) * 2 + 1);
    raycaster.setFromCamera(pointer, this.viewer.camera);
    const hits = raycaster.intersectObjects(this.viewer.shapes.meshes.filter((m) => m.userData.kind !== 'plane'));
    this.select(hits.length > 0 ? hits[0].object.userData.instances[hits[0].instanceId].body : -1);
  };

  V.Picking.prototype.select = function (b) {
    this.body = b;
    this.panel.hidden = b < 0;
    this.viewer.repaint();
  };

  V.Picking.prototype.update = function (f) {
    if (this.body < 0) return;
    const r = this.viewer.replay, b = this.body, body = r.bodies[b], k = f * r.bodyCount + b;
    let text = body.type + (body.type === 'dynamic' ? ', mass ' + body.mass.toPrecision(4) + ' kg' : '') +
      ', ' + body.shapes.length + ' shape' + (body.shapes.length === 1 ? '' : 's') + ' (' +
      body.shapes.map((s) => s.type).join(', ') + ')\n';
    if (r.overlays) text += (r.overlays.asleep[k] ? 'asleep' : 'awake') +
      (r.overlays.island[k] >= 0 ? ', island of \'' + r.bodies[r.overlays.island[k]].name + '\'' : '') + '\n';
    text += '\nposition (m)     ' + fmt(V.vec3(r.cairn.position, k)) + '\n';
    if (r.cairn.velocity) text += 'velocity (m/s)   ' + fmt(V.vec3(r.cairn.velocity, k)) + '\n';
    if (r.cairn.angularVelocity) text += 'ang. vel. (rad/s)' + fmt(V.vec3(r.cairn.angularVelocity, k)) + '\n';
    text += '\nforces (N)\n';
    const forces = V.bodyForces(r, b, f), net = [0, 0, 0];
    for (const fr of forces) { text += '  ' + fr.label + '\n    ' + fmt(fr.force) + '\n'; add(net, fr.force, 1); }
    text += '  sum\n    ' + fmt(net) + '\n';
    if (!r.overlays) text += '  (contact and joint forces are recorded only by cairn view --run)\n';
    this.panel.innerHTML = '';
    const name = document.createElement('div');
    name.className = 'name';
    name.textContent = body.name;
    this.panel.appendChild(name);
    this.panel.appendChild(document.createTextNode(text));
  };
})(CairnViewer);
