// The replay's data (docs/viewer.md, "Data format"): the JSON block the page
// carries, with every per-frame array decoded from base64 into a typed
// array once, at load. Frame f, body b of a 3-vector array is at
// 3 * (f * bodies + b); orientations are x, y, z, w.
'use strict';
var CairnViewer = CairnViewer || {};

(function (V) {
  function decode(b64, Type) {
    const text = atob(b64);
    const bytes = new Uint8Array(text.length);
    for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
    return new Type(bytes.buffer, 0, bytes.length / Type.BYTES_PER_ELEMENT);
  }

  function track(t) {
    return {
      time: decode(t.time, Float64Array),
      position: decode(t.position, Float32Array),
      orientation: decode(t.orientation, Float32Array),
      velocity: t.velocity ? decode(t.velocity, Float32Array) : null,
      angularVelocity: t.angular_velocity ? decode(t.angular_velocity, Float32Array) : null,
    };
  }

  function overlays(o) {
    if (!o) return null;
    const f32 = (k) => decode(o[k], Float32Array);
    return {
      asleep: decode(o.asleep, Uint8Array),
      island: decode(o.island, Int32Array),
      manifoldBegin: decode(o.manifold_begin, Uint32Array),
      pointBegin: decode(o.point_begin, Uint32Array),
      contactFrame: decode(o.contact_frame, Uint32Array),
      manifoldNormal: f32('manifold_normal'),
      manifoldFriction: f32('manifold_friction'),
      manifoldBody: decode(o.manifold_body, Int32Array),
      manifoldPoints: decode(o.manifold_points, Uint8Array),
      pointPosition: f32('point_position'),
      pointImpulse: f32('point_impulse'),
      jointAnchorA: f32('joint_anchor_a'),
      jointAnchorB: f32('joint_anchor_b'),
      jointAxis: f32('joint_axis'),
      jointError: f32('joint_error'),
      jointForceA: f32('joint_force_a'),
      jointForceB: f32('joint_force_b'),
    };
  }

  V.loadReplay = function (text) {
    const d = JSON.parse(text);
    if (d.format !== 'cairn replay 1') throw new Error('not a cairn replay (format ' + d.format + ')');
    const r = {
      title: d.title, source: d.source, notes: d.notes, dt: d.dt, substeps: d.substeps,
      gravity: d.gravity, frames: d.frames, bodies: d.bodies, joints: d.joints,
      cairn: track(d.cairn), bullet: d.bullet ? track(d.bullet) : null,
      overlays: overlays(d.overlays), parting: d.parting,
    };
    r.bodyCount = r.bodies.length;
    r.duration = r.frames > 0 ? r.cairn.time[r.frames - 1] : 0;
    // Contact impulses are the last substep's: force = impulse / (dt / substeps).
    r.impulseToForce = r.substeps / r.dt;
    r.shapeCount = r.bodies.reduce((n, b) => n + b.shapes.length, 0);
    return r;
  };

  // The last frame at or before time t (binary search: frames may be sparse).
  V.frameAt = function (replay, t) {
    const time = replay.cairn.time;
    let lo = 0, hi = replay.frames - 1;
    if (t >= time[hi]) return hi;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (time[mid] <= t + 1e-9) lo = mid; else hi = mid - 1;
    }
    return lo;
  };

  // Calls visit(manifold, firstPoint, pointCount) for each contact manifold
  // shown at frame f (a thinned frame shows the last kept one's).
  V.eachManifold = function (replay, f, visit) {
    const o = replay.overlays, shown = o.contactFrame[f];
    let p = o.pointBegin[shown];
    for (let m = o.manifoldBegin[shown]; m < o.manifoldBegin[shown + 1]; m++) {
      visit(m, p, o.manifoldPoints[m]);
      p += o.manifoldPoints[m];
    }
  };

  V.vec3 = function (array, index) { return [array[3 * index], array[3 * index + 1], array[3 * index + 2]]; };
})(CairnViewer);
