// Every shape drawn as itself, one THREE.InstancedMesh per geometry:
// boxes, spheres and cylinders share a unit geometry scaled per instance
// (so a 1,000-box pile is one draw call); capsules share one geometry per
// (radius, half height); each convex hull and triangle mesh has its own;
// planes are large squares. An instance's matrix is the body's pose (center
// of mass) times the shape's pose in the body times the scale.
'use strict';
var CairnViewer = CairnViewer || {};

(function (V) {
  const SEGMENTS = 24;

  // A capsule along y: a cylinder of half height hh capped by hemispheres,
  // revolved from its outline (three.js r111 has no capsule geometry).
  function capsuleGeometry(r, hh) {
    const outline = [];
    const n = SEGMENTS / 2;
    for (let i = 0; i <= n; i++) {  // bottom cap, from the pole up to the equator
      const a = -Math.PI / 2 + (i / n) * (Math.PI / 2);
      outline.push(new THREE.Vector2(r * Math.cos(a), -hh + r * Math.sin(a)));
    }
    for (let i = 0; i <= n; i++) {  // top cap, from the equator to the pole
      const a = (i / n) * (Math.PI / 2);
      outline.push(new THREE.Vector2(r * Math.cos(a), hh + r * Math.sin(a)));
    }
    outline[0].x = outline[outline.length - 1].x = 0;
    return new THREE.LatheBufferGeometry(outline, SEGMENTS);
  }

  // Triangles over the given vertices, flat-shaded (each face its own normal).
  function polyGeometry(vertices, triangles) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(vertices, 3));
    g.setIndex(triangles);
    const flat = g.toNonIndexed();
    flat.computeVertexNormals();
    return flat;
  }

  const unit = {};
  function unitGeometry(kind) {
    if (!unit[kind]) {
      if (kind === 'box') unit[kind] = new THREE.BoxBufferGeometry(1, 1, 1);
      else if (kind === 'sphere') unit[kind] = new THREE.SphereBufferGeometry(1, SEGMENTS, SEGMENTS / 2);
      else if (kind === 'cylinder') unit[kind] = new THREE.CylinderBufferGeometry(1, 1, 1, SEGMENTS);
      else if (kind === 'plane') unit[kind] = new THREE.PlaneBufferGeometry(1, 1);
    }
    return unit[kind];
  }

  // Diameter of a shape's bounding sphere (0 for planes), for scaling overlays.
  V.shapeSize = function (s) {
    switch (s.type) {
      case 'sphere': return 2 * s.radius;
      case 'box': return 2 * Math.hypot(s.half_extents[0], s.half_extents[1], s.half_extents[2]);
      case 'capsule': return 2 * (s.radius + s.half_height);
      case 'cylinder': return 2 * Math.hypot(s.radius, s.half_height);
      case 'convex_hull': case 'mesh': {
        let r = 0;
        for (let i = 0; i < s.vertices.length; i += 3)
          r = Math.max(r, Math.hypot(s.vertices[i], s.vertices[i + 1], s.vertices[i + 2]));
        return 2 * r;
      }
      default: return 0;
    }
  };

  // The geometry a shape is drawn with, the key of the instanced mesh it
  // joins, and its scale.
  function shapeGeometry(s, bodyIndex, shapeIndex, planeSize) {
    switch (s.type) {
      case 'box': return { key: 'box', scale: s.half_extents.map((h) => 2 * h) };
      case 'sphere': return { key: 'sphere', scale: [s.radius, s.radius, s.radius] };
      case 'cylinder': return { key: 'cylinder', scale: [s.radius, 2 * s.half_height, s.radius] };
      case 'plane': return { key: 'plane', scale: [planeSize, planeSize, 1] };
      case 'capsule': {
        const key = 'capsule ' + s.radius + ' ' + s.half_height;
        return { key, scale: [1, 1, 1], make: () => capsuleGeometry(s.radius, s.half_height) };
      }
      default: {  // convex_hull, mesh: one geometry each
        const key = s.type + ' ' + bodyIndex + ' ' + shapeIndex;
        return { key, scale: [1, 1, 1], make: () => polyGeometry(s.vertices, s.triangles) };
      }
    }
  }

  // A plane {normal n, offset d} as a square through n d facing along n
  // (PlaneBufferGeometry faces +z).
  function planePose(s) {
    const n = new THREE.Vector3().fromArray(s.normal).normalize();
    return {
      position: n.clone().multiplyScalar(s.offset),
      quaternion: new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 0, 1), n),
    };
  }

  // The instanced meshes of one engine's bodies. options: wireframe (Bullet's
  // overlay), color (wireframe colour), bodies (which bodies to draw),
  // planeSize (m).
  V.ShapeLayer = function (replay, options) {
    const groups = new Map();
    replay.bodies.forEach((body, b) => {
      if (!options.bodies(b)) return;
      body.shapes.forEach((s, k) => {
        const g = shapeGeometry(s, b, k, options.planeSize);
        if (!groups.has(g.key)) groups.set(g.key, { geometry: g.make ? g.make() : unitGeometry(g.key), instances: [] });
        let position = new THREE.Vector3().fromArray(s.position);
        let quaternion = new THREE.Quaternion().fromArray(s.orientation);
        if (s.type === 'plane') {
          const p = planePose(s);
          position = position.add(p.position);
          quaternion = quaternion.multiply(p.quaternion);
        }
        const local = new THREE.Matrix4().compose(position, quaternion, new THREE.Vector3().fromArray(g.scale));
        groups.get(g.key).instances.push({ body: b, shape: k, local });
      });
    });
    this.meshes = [];
    for (const [key, group] of groups) {
      const n = group.instances.length;
      let geometry = group.geometry, material;
      if (options.wireframe) {
        material = new THREE.MeshBasicMaterial({ color: options.color, wireframe: true, transparent: true, opacity: 0.8 });
      } else {
        // Per-instance colour: an instanced 'color' attribute read by the
        // vertex-colour path of the material (r111 has no setColorAt).
        geometry = geometry.clone();
        geometry.setAttribute('color', new THREE.InstancedBufferAttribute(new Float32Array(3 * n), 3));
        material = new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors,
          side: key === 'plane' || key.startsWith('mesh') ? THREE.DoubleSide : THREE.FrontSide });
      }
      const mesh = new THREE.InstancedMesh(geometry, material, n);
      mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
      mesh.frustumCulled = false;  // the bounds are the unit geometry's, not the instances'
      mesh.userData.instances = group.instances;
      mesh.userData.kind = key.split(' ')[0];
      this.meshes.push(mesh);
    }
  };

  const bodyMatrix = new THREE.Matrix4(), world = new THREE.Matrix4();
  const position = new THREE.Vector3(), quaternion = new THREE.Quaternion(), one = new THREE.Vector3(1, 1, 1);

  // Poses of `track` at frame f.
  V.ShapeLayer.prototype.update = function (track, f, bodyCount) {
    for (const mesh of this.meshes) {
      const instances = mesh.userData.instances, out = mesh.instanceMatrix.array;
      for (let i = 0; i < instances.length; i++) {
        const k = f * bodyCount + instances[i].body;
        position.fromArray(track.position, 3 * k);
        quaternion.fromArray(track.orientation, 4 * k);
        bodyMatrix.compose(position, quaternion, one);
        world.multiplyMatrices(bodyMatrix, instances[i].local).toArray(out, 16 * i);
      }
      mesh.instanceMatrix.needsUpdate = true;
    }
  };

  // colorOf(body) -> THREE.Color, for every instance.
  V.ShapeLayer.prototype.paint = function (colorOf) {
    for (const mesh of this.meshes) {
      const attribute = mesh.geometry.getAttribute('color');
      if (!attribute) continue;
      mesh.userData.instances.forEach((inst, i) => colorOf(inst.body).toArray(attribute.array, 3 * i));
      attribute.needsUpdate = true;
    }
  };

  V.ShapeLayer.prototype.setVisible = function (visible) {
    for (const mesh of this.meshes) mesh.visible = visible;
  };

  // Instances drawn now: what the browser test compares with the shape count.
  V.ShapeLayer.prototype.drawnInstances = function () {
    return this.meshes.reduce((n, m) => n + (m.visible ? m.count : 0), 0);
  };

  V.ShapeLayer.prototype.instancesByKind = function () {
    const out = {};
    for (const m of this.meshes) out[m.userData.kind] = (out[m.userData.kind] || 0) + m.count;
    return out;
  };
})(CairnViewer);
