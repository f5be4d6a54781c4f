// Every shape drawn as itself, one batch per geometry: boxes, spheres and
// cylinders share a unit geometry scaled per instance (so a 1,000-box pile
// is one draw call); capsules share one geometry per (radius, half height);
// each convex hull and triangle mesh has its own; planes are large squares.
// An instance's matrix is the body's pose (center of mass) times the
// shape's pose in the body times the scale.
//
// Why batches and not THREE.InstancedMesh: Chromium without a GPU (headless,
// as the browser tests run it) draws WebGL with SwiftShader, whose Vulkan
// draw command runs one whole draw per instance (vk::CommandBuffer's
// CmdDrawBase::draw loops over the instances, calling Renderer::draw for
// each), about 0.1 ms apiece: 1,001 instanced boxes cost 110 ms a frame.
// A batch is the geometry repeated once per instance, each vertex carrying
// its instance's index; the instances' matrices and colours live in a float
// texture the vertex shader reads (four RGBA texels an instance: the three
// rows of the affine matrix, then the colour). It draws as one plain draw
// call on any WebGL, and a frame changes only the texture, 64 bytes an
// instance, uploaded when the shown frame changes.
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

  // Texels of an instance in the instance texture, and instances per texture
  // row: a power of two, so the shader's t / width is exact in float.
  const TEXELS = 4, PER_ROW = 256, WIDTH = TEXELS * PER_ROW;

  // The vertex shader's instance matrix and colour, read from the texture
  // (three.js's chunks apply `instanceMatrix` under USE_INSTANCING, defined
  // here after the program's prefix, so no instanced attribute is declared).
  const INSTANCE_DECLARATIONS = [
    'uniform sampler2D instanceData;',
    'uniform vec2 instanceDataSize;',
    'attribute float instanceIndex;',
    'vec4 instanceTexel(float k) {',
    '  float t = ' + TEXELS + '.0 * instanceIndex + k, row = floor(t / instanceDataSize.x);',
    '  return texture2D(instanceData, (vec2(t - row * instanceDataSize.x, row) + 0.5) / instanceDataSize);',
    '}',
    '#define USE_INSTANCING',
  ].join('\n');
  const INSTANCE_MAIN = [
    'void main() {',
    '  vec4 r0 = instanceTexel(0.0), r1 = instanceTexel(1.0), r2 = instanceTexel(2.0);',
    '  mat4 instanceMatrix = mat4(r0.x, r1.x, r2.x, 0.0, r0.y, r1.y, r2.y, 0.0,',
    '                             r0.z, r1.z, r2.z, 0.0, r0.w, r1.w, r2.w, 1.0);',
  ].join('\n');
  const INSTANCE_COLOR = '#ifdef USE_COLOR\n  vColor.xyz = instanceTexel(3.0).rgb;\n#endif';

  // Makes `material` read its instances from `texture` (one program for
  // every batch: three.js keys programs by this function's text).
  function readInstances(material, texture) {
    material.onBeforeCompile = function (shader) {
      shader.uniforms.instanceData = { value: this.userData.instanceData };
      shader.uniforms.instanceDataSize = { value: this.userData.instanceDataSize };
      shader.vertexShader = INSTANCE_DECLARATIONS + '\n' + shader.vertexShader
        .replace('void main() {', INSTANCE_MAIN)
        .replace('#include <color_vertex>', INSTANCE_COLOR);
    };
    material.userData.instanceData = texture;
    material.userData.instanceDataSize = new THREE.Vector2(texture.image.width, texture.image.height);
  }

  // `base` repeated n times; instanceIndex says which copy a vertex is.
  function batchGeometry(base, n) {
    const g = new THREE.BufferGeometry(), v = base.getAttribute('position').count;
    for (const name of ['position', 'normal']) {
      const a = base.getAttribute(name).array, out = new Float32Array(a.length * n);
      for (let i = 0; i < n; i++) out.set(a, i * a.length);
      g.setAttribute(name, new THREE.BufferAttribute(out, 3));
    }
    const index = new Float32Array(v * n);
    for (let i = 0; i < n; i++) index.fill(i, i * v, (i + 1) * v);
    g.setAttribute('instanceIndex', new THREE.BufferAttribute(index, 1));
    if (base.index) {
      const a = base.index.array, out = new (v * n > 65535 ? Uint32Array : Uint16Array)(a.length * n);
      for (let i = 0; i < n; i++) for (let j = 0; j < a.length; j++) out[i * a.length + j] = a[j] + i * v;
      g.setIndex(new THREE.BufferAttribute(out, 1));
    }
    return g;
  }

  // Ray against each instance's own geometry, as THREE.InstancedMesh's
  // raycast does: hits carry the instanceId.
  const probe = new THREE.Mesh(), probeHits = [], instanceWorld = new THREE.Matrix4();
  function raycastInstances(raycaster, intersects) {
    probe.geometry = this.userData.base;
    probe.material = this.material;
    for (let i = 0; i < this.count; i++) {
      instanceWorld.fromArray(this.userData.matrices, 16 * i).premultiply(this.matrixWorld);
      probe.matrixWorld = instanceWorld;
      probe.raycast(raycaster, probeHits);
      for (const hit of probeHits) { hit.instanceId = i; hit.object = this; intersects.push(hit); }
      probeHits.length = 0;
    }
  }

  // The batches of one engine's bodies. options: wireframe (Bullet's
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
      const texture = new THREE.DataTexture(new Float32Array(4 * WIDTH * Math.ceil(n / PER_ROW)), WIDTH,
        Math.ceil(n / PER_ROW), THREE.RGBAFormat, THREE.FloatType);
      const material = options.wireframe
        ? new THREE.MeshBasicMaterial({ color: options.color, wireframe: true, transparent: true, opacity: 0.8 })
        : new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors,
          side: key === 'plane' || key.startsWith('mesh') ? THREE.DoubleSide : THREE.FrontSide });
      readInstances(material, texture);
      const mesh = new THREE.Mesh(batchGeometry(group.geometry, n), material);
      mesh.count = n;
      mesh.raycast = raycastInstances;
      mesh.frustumCulled = false;  // the bounds are the unit geometry's, not the instances'
      mesh.userData = { base: group.geometry, instances: group.instances, kind: key.split(' ')[0],
                        texture, matrices: new Float32Array(16 * n) };
      this.meshes.push(mesh);
    }
  };

  const bodyMatrix = new THREE.Matrix4(), world = new THREE.Matrix4();
  const position = new THREE.Vector3(), quaternion = new THREE.Quaternion(), one = new THREE.Vector3(1, 1, 1);

  // Poses of `track` at frame f.
  V.ShapeLayer.prototype.update = function (track, f, bodyCount) {
    for (const mesh of this.meshes) {
      const { instances, matrices, texture } = mesh.userData, out = texture.image.data;
      for (let i = 0; i < instances.length; i++) {
        const k = f * bodyCount + instances[i].body;
        position.fromArray(track.position, 3 * k);
        quaternion.fromArray(track.orientation, 4 * k);
        bodyMatrix.compose(position, quaternion, one);
        world.multiplyMatrices(bodyMatrix, instances[i].local).toArray(matrices, 16 * i);
        const e = world.elements, t = 4 * TEXELS * i;  // rows 0-2 of the column-major matrix
        for (let r = 0; r < 3; r++) {
          out[t + 4 * r] = e[r]; out[t + 4 * r + 1] = e[4 + r]; out[t + 4 * r + 2] = e[8 + r]; out[t + 4 * r + 3] = e[12 + r];
        }
      }
      texture.needsUpdate = true;
    }
  };

  // colorOf(body) -> THREE.Color, for every instance.
  V.ShapeLayer.prototype.paint = function (colorOf) {
    for (const mesh of this.meshes) {
      if (!mesh.material.vertexColors) continue;
      const { instances, texture } = mesh.userData;
      instances.forEach((inst, i) => colorOf(inst.body).toArray(texture.image.data, 4 * TEXELS * i + 12));
      texture.needsUpdate = true;
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
