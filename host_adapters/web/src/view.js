// The 3D view: every body's triangles over one shared position / colour buffer (updated in place
// each frame), the colliders moved with each frame's poses, pins as small markers; z is up.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { ConvexGeometry } from 'three/examples/jsm/geometries/ConvexGeometry.js';

const BACKGROUND = 0xf3f4f6;
const COLLIDER_COLOR = 0x7f93a8;
const PIN_COLOR = 0x1f2933;
const DRAG_COLOR = 0xe8590c;
const VIEW_DIRECTION = new THREE.Vector3(0.9, -1.3, 1.05).normalize(); // from the south east, 36° up
const CREASE_COS = Math.cos(THREE.MathUtils.degToRad(35));

/**
 * The colour attribute holds the page's colours as given (errorColor's sRGB values, exactly);
 * the fragment shader reads them as sRGB, so a lit face shows the colour function's colour.
 */
function srgbVertexColors(material) {
  material.onBeforeCompile = (shader) => {
    shader.fragmentShader = shader.fragmentShader.replace(
      '#include <color_fragment>',
      '#if defined( USE_COLOR ) || defined( USE_COLOR_ALPHA )\n\tdiffuseColor *= sRGBTransferEOTF( vColor );\n#endif',
    );
  };
  return material;
}

function colliderGeometry(c, planeSize) {
  switch (c.shape) {
    case 'sphere':
      return new THREE.SphereGeometry(c.radius, 64, 40);
    case 'box': {
      const [x, y, z] = c.half_extents;
      return new THREE.BoxGeometry(2 * x, 2 * y, 2 * z);
    }
    case 'capsule': // three's capsule runs along y, embra's along local z
      return new THREE.CapsuleGeometry(c.radius, 2 * c.half_length, 12, 40).rotateX(Math.PI / 2);
    case 'plane':
      return new THREE.PlaneGeometry(planeSize, planeSize, 1, 1);
    case 'convex': {
      const points = [];
      for (let k = 0; k + 2 < c.vertices.length; k += 3) points.push(new THREE.Vector3(c.vertices[k], c.vertices[k + 1], c.vertices[k + 2]));
      return new ConvexGeometry(points);
    }
    case 'mesh': {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(c.vertices, 3));
      g.setIndex(c.triangles);
      g.computeVertexNormals();
      return g;
    }
    default:
      return null;
  }
}

/** Edges of one triangle only, and edges between triangles folded by more than 35 degrees. */
function featureEdges(triangles, positions) {
  const normal = (t) => {
    const [a, b, c] = [0, 1, 2].map((k) => new THREE.Vector3().fromArray(positions, 3 * triangles[3 * t + k]));
    return b.sub(a).cross(c.sub(a)).normalize();
  };
  const edges = new Map();
  for (let t = 0; 3 * t < triangles.length; t++) {
    for (let k = 0; k < 3; k++) {
      const i = triangles[3 * t + k];
      const j = triangles[3 * t + ((k + 1) % 3)];
      const key = i < j ? `${i},${j}` : `${j},${i}`;
      const entry = edges.get(key);
      if (entry) entry.push(t);
      else edges.set(key, [t]);
    }
  }
  const out = [];
  for (const [key, tris] of edges) {
    const crease = tris.length === 2 && normal(tris[0]).dot(normal(tris[1])) < CREASE_COS;
    if (tris.length === 1 || crease) out.push(...key.split(',').map(Number));
  }
  return out;
}

export class View {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(BACKGROUND);
    this.canvas = this.renderer.domElement;
    container.appendChild(this.canvas);

    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.01, 1000);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(4, -6, 4);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.enableDamping = true;
    this.controls.dampingFactor = 0.15;
    this.controls.addEventListener('change', () => { this.dirty = true; });

    // Light that shows folds: a soft sky / ground fill, a key light from the front left and above,
    // a weaker rim light from behind on the right.
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8a857d, 0.95));
    this.key = new THREE.DirectionalLight(0xffffff, 2.6);
    this.key.position.set(-2.2, -1.2, 2.4);
    this.scene.add(this.key);
    this.rim = new THREE.DirectionalLight(0xffffff, 0.55);
    this.rim.position.set(2.0, 2.5, 1.2);
    this.scene.add(this.rim);

    this.grid = null;
    this.bodyGroup = new THREE.Group();
    this.colliderGroup = new THREE.Group();
    this.pinGroup = new THREE.Group();
    this.scene.add(this.bodyGroup, this.colliderGroup, this.pinGroup);

    this.dragMarker = new THREE.Mesh(new THREE.SphereGeometry(1, 20, 14), new THREE.MeshBasicMaterial({ color: DRAG_COLOR }));
    this.dragLine = new THREE.Line(new THREE.BufferGeometry().setAttribute('position', new THREE.Float32BufferAttribute(6, 3)),
      new THREE.LineBasicMaterial({ color: DRAG_COLOR }));
    this.hoverMarker = new THREE.Mesh(new THREE.SphereGeometry(1, 16, 10), new THREE.MeshBasicMaterial({ color: 0x111111 }));
    this.dragMarker.visible = this.dragLine.visible = this.hoverMarker.visible = false;
    this.scene.add(this.dragMarker, this.dragLine, this.hoverMarker);

    this.raycaster = new THREE.Raycaster();
    this.particles = 0;
    this.meshes = [];
    this.edgeLines = []; // the line segments of edge-only bodies
    this.colliders = [];
    this.pins = [];
    this.sceneSize = 1;
    this.framed = false;
    this.heldCollider = -1;
    this.drag = null;
    this.dirty = true;

    this.resize();
    new ResizeObserver(() => this.resize()).observe(container);
  }

  resize() {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (w === 0 || h === 0) return;
    this.renderer.setSize(w, h, false);
    this.canvas.style.width = `${w}px`;
    this.canvas.style.height = `${h}px`;
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  /** Builds the bodies, colliders and pins of a scene message (replacing any previous scene). */
  setScene(scene) {
    for (const group of [this.bodyGroup, this.colliderGroup, this.pinGroup]) {
      for (const child of [...group.children]) {
        group.remove(child);
        child.traverse((o) => { o.geometry?.dispose(); o.material?.dispose(); });
      }
    }
    const n = scene.particles;
    this.particles = n;
    this.position = new THREE.BufferAttribute(new Float32Array(3 * n), 3).setUsage(THREE.DynamicDrawUsage);
    this.color = new THREE.BufferAttribute(new Float32Array(3 * n).fill(0.8), 3).setUsage(THREE.DynamicDrawUsage);
    this.edgeLines = [];
    this.meshes = scene.bodies.map((body) => {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', this.position);
      geometry.setAttribute('color', this.color);
      geometry.setIndex(new (n > 65535 ? THREE.Uint32BufferAttribute : THREE.Uint16BufferAttribute)(body.triangles, 1));
      // Panels are planar: flat shading shows every fold between them; cloth is shaded smooth.
      const material = srgbVertexColors(new THREE.MeshStandardMaterial({
        vertexColors: true, side: THREE.DoubleSide, flatShading: !!body.panel_mesh,
        roughness: 0.62, metalness: 0.0,
        polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
      }));
      const mesh = new THREE.Mesh(geometry, material);
      mesh.userData.body = body.index;
      mesh.userData.smooth = !body.panel_mesh;
      mesh.userData.triangles = body.triangles;
      // Outlines (every panel's border, a cloth's border, creases), found at the first frame.
      const lines = new THREE.BufferGeometry();
      lines.setAttribute('position', this.position);
      const outline = new THREE.LineSegments(lines, new THREE.LineBasicMaterial({ color: 0x3d434a, transparent: true, opacity: 0.55 }));
      outline.frustumCulled = false;
      mesh.userData.outline = outline;
      this.bodyGroup.add(mesh, outline);
      if (body.edges?.length) { // an edge-only body (a net, a cable): its edges as lines
        const net = new THREE.BufferGeometry();
        net.setAttribute('position', this.position);
        net.setAttribute('color', this.color);
        net.setIndex(new (n > 65535 ? THREE.Uint32BufferAttribute : THREE.Uint16BufferAttribute)(body.edges, 1));
        const lines = new THREE.LineSegments(net, srgbVertexColors(new THREE.LineBasicMaterial({ vertexColors: true })));
        lines.frustumCulled = false;
        this.edgeLines.push(lines);
        this.bodyGroup.add(lines);
      }
      return mesh;
    });

    this.colliders = scene.colliders.map((c) => {
      const geometry = colliderGeometry(c, 1);
      const plane = c.shape === 'plane';
      const material = new THREE.MeshStandardMaterial({
        color: COLLIDER_COLOR, roughness: 0.85, metalness: 0,
        transparent: true, opacity: plane ? 0.16 : 0.42, depthWrite: false,
        side: plane || c.shape === 'mesh' ? THREE.DoubleSide : THREE.FrontSide,
      });
      const object = new THREE.Mesh(geometry || new THREE.BufferGeometry(), material);
      object.renderOrder = 1; // after the opaque bodies
      object.userData.collider = c.index;
      object.userData.plane = plane;
      if (!plane && geometry) {
        const edges = new THREE.LineSegments(new THREE.EdgesGeometry(geometry, 30),
          new THREE.LineBasicMaterial({ color: 0x5b6b7c, transparent: true, opacity: 0.5 }));
        if (c.shape !== 'sphere' && c.shape !== 'capsule') object.add(edges);
      }
      this.setPose(object, c.position, c.rotation);
      this.colliderGroup.add(object);
      return object;
    });

    this.pins = scene.pins.map((pin) => {
      const marker = new THREE.Mesh(new THREE.SphereGeometry(1, 16, 10), new THREE.MeshBasicMaterial({ color: PIN_COLOR }));
      marker.userData.particle = pin.particle;
      this.pinGroup.add(marker);
      return marker;
    });
    this.applySizes();
    this.dirty = true;
  }

  /** Markers and planes sized by the framed scene's size. */
  applySizes() {
    const size = this.sceneSize * 0.018;
    for (const marker of [...this.pins, this.dragMarker]) marker.scale.setScalar(size);
    this.hoverMarker.scale.setScalar(size * 0.7);
    this.colliders.forEach((object) => {
      if (object.userData.plane) object.scale.setScalar(this.sceneSize * 8);
    });
  }

  setPose(object, p, q) {
    object.position.set(p[0], p[1], p[2]);
    object.quaternion.set(q[1], q[2], q[3], q[0]).normalize(); // embra: w x y z
    object.updateMatrixWorld(true);
  }

  /** One frame: positions (3N floats) and collider poses (7C floats: x y z, w qx qy qz). */
  setFrame(positions, poses) {
    if (!this.position || positions.length !== 3 * this.particles) return;
    this.position.array.set(positions);
    this.position.needsUpdate = true;
    for (const mesh of this.meshes) {
      const lines = mesh.userData.outline.geometry;
      if (!lines.index) lines.setIndex(featureEdges(mesh.userData.triangles, positions));
    }
    for (const mesh of this.meshes) {
      if (mesh.userData.smooth) mesh.geometry.computeVertexNormals();
      mesh.geometry.boundingSphere = null; // recomputed for culling and picking
      mesh.geometry.boundingBox = null;
    }
    if (poses) {
      this.colliders.forEach((object, c) => {
        if (c === this.heldCollider || poses.length < 7 * (c + 1)) return;
        const o = 7 * c;
        this.setPose(object, [poses[o], poses[o + 1], poses[o + 2]], [poses[o + 3], poses[o + 4], poses[o + 5], poses[o + 6]]);
      });
    }
    for (const marker of this.pins) marker.position.fromArray(positions, 3 * marker.userData.particle);
    this.updateDragLine();
    this.dirty = true;
  }

  /** Vertex colours: a function from particle index to [r, g, b] (errorColor's values, sRGB). */
  setColors(colorOf) {
    if (!this.color) return;
    const a = this.color.array;
    for (let i = 0; i < this.particles; i++) {
      const c = colorOf(i);
      a[3 * i] = c[0];
      a[3 * i + 1] = c[1];
      a[3 * i + 2] = c[2];
    }
    this.color.needsUpdate = true;
    this.dirty = true;
  }

  setPinsVisible(on) {
    this.pinGroup.visible = on;
    this.dirty = true;
  }

  particle(i, out = new THREE.Vector3()) {
    return out.fromArray(this.position.array, 3 * i);
  }

  /** Frames the camera on the bodies and colliders (planes excepted), looking down from the south east. */
  frameAll() {
    const points = [];
    const p = new THREE.Vector3();
    for (let i = 0; i < this.particles; i++) {
      if (Number.isFinite(this.position.array[3 * i])) points.push(this.particle(i, new THREE.Vector3()));
    }
    for (const object of this.colliders) {
      if (object.userData.plane) continue;
      const vertices = object.geometry.attributes.position;
      if (!vertices) continue;
      const stride = Math.max(1, Math.floor(vertices.count / 4000));
      for (let k = 0; k < vertices.count; k += stride) points.push(p.fromBufferAttribute(vertices, k).applyMatrix4(object.matrixWorld).clone());
    }
    if (points.length === 0) return;
    const box = new THREE.Box3().setFromPoints(points);
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const radius = Math.max(sphere.radius, 1e-3);
    // Centre the points' extent across the view, then back off to the nearest distance at which
    // every point is inside the frustum (with a margin).
    const forward = VIEW_DIRECTION.clone().negate();
    const right = new THREE.Vector3().crossVectors(forward, this.camera.up).normalize();
    const up = new THREE.Vector3().crossVectors(right, forward);
    const lo = [Infinity, Infinity];
    const hi = [-Infinity, -Infinity];
    for (const q of points) {
      const d = q.clone().sub(sphere.center);
      const xy = [d.dot(right), d.dot(up)];
      for (let k = 0; k < 2; k++) {
        lo[k] = Math.min(lo[k], xy[k]);
        hi[k] = Math.max(hi[k], xy[k]);
      }
    }
    const target = sphere.center.clone()
      .addScaledVector(right, (lo[0] + hi[0]) / 2)
      .addScaledVector(up, (lo[1] + hi[1]) / 2);
    const tanV = Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2) * 0.88;
    const tanH = tanV * this.camera.aspect;
    let distance = 0;
    for (const q of points) {
      const d = q.clone().sub(target);
      const depth = d.dot(VIEW_DIRECTION); // towards the camera
      distance = Math.max(distance, depth + Math.abs(d.dot(right)) / tanH, depth + Math.abs(d.dot(up)) / tanV);
    }
    this.controls.target.copy(target);
    this.camera.position.copy(target).addScaledVector(VIEW_DIRECTION, distance);
    this.camera.near = distance / 200;
    this.camera.far = distance * 50;
    this.camera.updateProjectionMatrix();
    this.controls.update();

    this.sceneSize = radius;
    this.applySizes();

    if (this.grid) {
      this.scene.remove(this.grid);
      this.grid.geometry.dispose();
      this.grid.material.dispose();
    }
    const step = 10 ** Math.floor(Math.log10(radius / 2));
    const divisions = Math.min(200, Math.ceil((radius * 6) / step));
    this.grid = new THREE.GridHelper(divisions * step, divisions, 0xc3c8cf, 0xdde0e4);
    this.grid.rotation.x = Math.PI / 2; // into the xy plane
    this.grid.position.set(sphere.center.x, sphere.center.y, box.min.z - radius * 0.01);
    this.grid.material.transparent = true;
    this.grid.material.opacity = 0.8;
    this.scene.add(this.grid);
    this.framed = true;
    this.dirty = true;
  }

  ndc(clientX, clientY) {
    const rect = this.canvas.getBoundingClientRect();
    return new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
  }

  ray(clientX, clientY) {
    this.raycaster.setFromCamera(this.ndc(clientX, clientY), this.camera);
    return this.raycaster.ray;
  }

  /** The particle nearest the hit point of the body triangle under the cursor, or null. */
  pickParticle(clientX, clientY) {
    this.ray(clientX, clientY);
    const hit = this.raycaster.intersectObjects(this.meshes, false)[0];
    if (!hit || !hit.face) return null;
    let best = null;
    let bestDistance = Infinity;
    const p = new THREE.Vector3();
    for (const i of [hit.face.a, hit.face.b, hit.face.c]) {
      const d = this.particle(i, p).distanceToSquared(hit.point);
      if (d < bestDistance) {
        bestDistance = d;
        best = i;
      }
    }
    return { particle: best, point: hit.point.clone() };
  }

  /** The collider under the cursor: its index and the hit point, or null. */
  /** The scene pin whose dot is under the cursor ({index, point}), or null. */
  pickPin(clientX, clientY) {
    if (!this.pinGroup.visible) return null;
    this.ray(clientX, clientY);
    const hit = this.raycaster.intersectObjects(this.pins, false)[0];
    return hit ? { index: this.pins.indexOf(hit.object), point: hit.object.position.clone() } : null;
  }

  pickCollider(clientX, clientY) {
    this.ray(clientX, clientY);
    const hit = this.raycaster.intersectObjects(this.colliders, false)[0];
    return hit ? { index: hit.object.userData.collider, point: hit.point.clone() } : null;
  }

  /** The plane through `point` facing the camera. */
  cameraPlane(point) {
    const normal = this.camera.getWorldDirection(new THREE.Vector3()).negate();
    return new THREE.Plane().setFromNormalAndCoplanarPoint(normal, point);
  }

  /** Where the cursor's ray meets `plane`, or null. */
  onPlane(clientX, clientY, plane) {
    return this.ray(clientX, clientY).intersectPlane(plane, new THREE.Vector3());
  }

  moveCollider(index, position) {
    const object = this.colliders[index];
    if (!object) return;
    object.position.copy(position);
    object.updateMatrixWorld(true);
    this.dirty = true;
  }

  colliderPosition(index) {
    return this.colliders[index]?.position.clone();
  }

  colliderRotation(index) {
    const q = this.colliders[index]?.quaternion;
    return q ? [q.w, q.x, q.y, q.z] : [1, 0, 0, 0];
  }

  /** The drag feedback: a marker at the target and a line from the particle; null hides it. */
  showDrag(particle, target) {
    const on = particle !== null && target !== null;
    this.drag = on ? { particle, target: target.clone() } : null;
    this.dragMarker.visible = this.dragLine.visible = on;
    if (on) this.dragMarker.position.copy(target);
    this.updateDragLine();
    this.dirty = true;
  }

  updateDragLine() {
    if (!this.drag) return;
    const line = this.dragLine.geometry.attributes.position;
    const p = this.particle(this.drag.particle);
    const t = this.drag.target;
    line.setXYZ(0, p.x, p.y, p.z);
    line.setXYZ(1, t.x, t.y, t.z);
    line.needsUpdate = true;
    this.dragLine.geometry.computeBoundingSphere();
  }

  showHover(particle) {
    this.hoverMarker.visible = particle !== null;
    if (particle !== null) this.particle(particle, this.hoverMarker.position);
    this.dirty = true;
  }

  /** A particle's page pixel coordinates. */
  screenOf(i) {
    return this.screenOfPoint(this.particle(i));
  }

  /** A world point's page pixel coordinates. */
  screenOfPoint(point) {
    const p = new THREE.Vector3().copy(point).project(this.camera);
    const rect = this.canvas.getBoundingClientRect();
    return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
  }

  /** Called every animation frame: renders when something changed. */
  tick() {
    if (this.controls.update()) this.dirty = true;
    if (!this.dirty) return;
    this.renderer.render(this.scene, this.camera);
    this.dirty = false;
  }
}
