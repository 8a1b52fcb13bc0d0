// The 3-D view of one pane: the world (triangles, a recording's point-cloud map), the trajectory,
// the agent, and the sensor's returns at the selected step, with orbit/zoom (three.js).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { turbo } from './colormap.js';

export class View3D {
  constructor(container) {
    this.container = container;
    // No multisampling and no preserved drawing buffer: in software rendering each costs a
    // large share of a frame. Readers of the pixels (tests) call render(true) first, in the same task.
    this.renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: false });
    this.renderer.setPixelRatio(1);
    this.renderer.setClearColor(0xfcfcfc);
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(50, 1, 0.05, 500);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => { this.dirty = true; });
    this.scene.add(new THREE.AmbientLight(0xffffff, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.8);
    sun.position.set(3, -5, 8);
    this.scene.add(sun);
    this.world = new THREE.Group();
    this.scene.add(this.world);
    this.dirty = true;
    this.frames = 0;
    // While the slider moves (or plays), draw at a reduced resolution: a software renderer's time
    // goes with the pixels. Full resolution returns when the motion stops.
    this.motionScale = new URLSearchParams(window.location.search).get('motion_scale') === '1' ? 1 : 0.6;
    this.scale = 1;
    // A click without a drag on the floor (z = 0) calls onFloorClick(x, y), when set.
    const canvasEl = this.renderer.domElement;
    canvasEl.addEventListener('pointerdown', (e) => { this.down = [e.clientX, e.clientY]; });
    canvasEl.addEventListener('pointerup', (e) => {
      if (!this.onFloorClick || !this.down || Math.hypot(e.clientX - this.down[0], e.clientY - this.down[1]) > 4) return;
      const r = canvasEl.getBoundingClientRect();
      const ndc = new THREE.Vector2(((e.clientX - r.left) / r.width) * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1);
      const ray = new THREE.Raycaster();
      ray.setFromCamera(ndc, this.camera);
      const hit = new THREE.Vector3();
      if (ray.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 0, 1), 0), hit)) this.onFloorClick(hit.x, hit.y);
    });
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth), h = Math.max(1, this.container.clientHeight);
    this.renderer.setPixelRatio(this.scale);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  // A world blob: triangles as a light, see-through surface with its edges, and any points.
  setWorld(blob) {
    this.world.clear();
    const { header, arrays } = blob;
    if (arrays.triangles && arrays.triangles.length) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(arrays.triangles, 3));
      g.computeVertexNormals();
      const surface = new THREE.Mesh(g, new THREE.MeshLambertMaterial({
        color: 0xb0bec5, transparent: true, opacity: 0.35, side: THREE.DoubleSide, depthWrite: false,
      }));
      this.world.add(surface);
      this.world.add(new THREE.LineSegments(new THREE.EdgesGeometry(g, 25), new THREE.LineBasicMaterial({ color: 0x546e7a })));
    }
    if (arrays.points && arrays.points.length) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(arrays.points, 3));
      // A map stays in the background: the step's own returns are drawn over it.
      this.world.add(new THREE.Points(g, new THREE.PointsMaterial({ color: 0xb0bec5, size: 1, sizeAttenuation: false,
        transparent: true, opacity: 0.5, depthWrite: false })));
    }
    if (header.walkable && header.walkable.length > 2) {
      const pts = header.walkable.map(([x, y]) => new THREE.Vector3(x, y, 0.001));
      pts.push(pts[0].clone());
      this.world.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: 0x8d6e63 })));
    }
    if (header.bounds) this.frame(header.bounds);
    this.dirty = true;
  }

  // Looks at the box from the south, above, far enough that its bounding sphere fits the view.
  frame([[x0, y0, z0], [x1, y1, z1]]) {
    const c = new THREE.Vector3((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2);
    const radius = 0.5 * Math.hypot(x1 - x0, y1 - y0, z1 - z0) || 1;
    const half = THREE.MathUtils.degToRad(this.camera.fov / 2);
    const halfH = Math.atan(Math.tan(half) * this.camera.aspect);
    const distance = (0.85 * radius) / Math.sin(Math.min(half, halfH));
    const direction = new THREE.Vector3(0.1, -0.8, 0.75).normalize();
    this.camera.position.copy(c).addScaledVector(direction, distance);
    this.controls.target.copy(c);
    this.controls.update();
    this.framed = [[x0, y0, z0], [x1, y1, z1]];
  }

  // The path, thinned to at most 4000 vertices: a software renderer draws a 50 000-vertex line at
  // a few frames per second, and at this scale the thinned path looks the same.
  setTrajectory(x, y, z) {
    if (this.trajectory) this.scene.remove(this.trajectory);
    const stride = Math.max(1, Math.ceil(x.length / 4000));
    const n = Math.ceil(x.length / stride), pos = new Float32Array(3 * n);
    for (let j = 0; j < n; j++) {
      const i = Math.min(x.length - 1, j * stride);
      pos[3 * j] = x[i];
      pos[3 * j + 1] = y[i];
      pos[3 * j + 2] = (z ? z[i] : 0) + 0.01;
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    this.trajectory = new THREE.Line(g, new THREE.LineBasicMaterial({ color: 0x9fa8da }));
    this.scene.add(this.trajectory);
    this.dirty = true;
  }

  // The agent: a cone along its heading at (x, y, z).
  setAgent(x, y, z, heading) {
    if (!this.agent) {
      this.agent = new THREE.Mesh(new THREE.ConeGeometry(0.12, 0.4, 16), new THREE.MeshLambertMaterial({ color: 0xc0392b }));
      this.scene.add(this.agent);
    }
    this.agent.position.set(x, y, z + 0.12);
    this.agent.rotation.set(0, 0, heading - Math.PI / 2);  // the cone points along +y before turning
    this.dirty = true;
  }

  // Returns: world-frame points colored by range (turbo, 0 .. maxRange); the rows the model keeps
  // drawn larger, the others small and faded.
  setReturns(points, range, kept, maxRange) {
    const n = range.length;
    if (!this.returns) {
      this.returns = [true, false].map((isKept) => {
        const g = new THREE.BufferGeometry();
        const m = new THREE.PointsMaterial({ size: isKept ? 4 : 1.5, sizeAttenuation: false, vertexColors: true,
          transparent: !isKept, opacity: isKept ? 1 : 0.4, depthWrite: isKept });
        const p = new THREE.Points(g, m);
        p.frustumCulled = false;
        this.scene.add(p);
        return { points: p, capacity: 0 };
      });
    }
    let nk = 0;
    for (let i = 0; i < n; i++) nk += kept[i] ? 1 : 0;
    const counts = [nk, n - nk];
    this.returns.forEach((r, which) => {
      const need = Math.max(counts[which], 1);
      if (r.capacity < need) {
        r.capacity = Math.max(need, 2 * r.capacity);
        r.position = new THREE.BufferAttribute(new Float32Array(3 * r.capacity), 3);
        r.color = new THREE.BufferAttribute(new Float32Array(3 * r.capacity), 3);
        r.position.setUsage(THREE.DynamicDrawUsage);
        r.color.setUsage(THREE.DynamicDrawUsage);
        r.points.geometry.setAttribute('position', r.position);
        r.points.geometry.setAttribute('color', r.color);
      }
      r.fill = 0;
    });
    for (let i = 0; i < n; i++) {
      const r = this.returns[kept[i] ? 0 : 1];
      const j = r.fill++;
      r.position.array[3 * j] = points[3 * i];
      r.position.array[3 * j + 1] = points[3 * i + 1];
      r.position.array[3 * j + 2] = points[3 * i + 2];
      turbo(range[i] / maxRange, r.color.array, 3 * j);
    }
    for (const r of this.returns) {
      r.points.geometry.setDrawRange(0, r.fill);
      r.position.needsUpdate = true;
      r.color.needsUpdate = true;
    }
    this.dirty = true;
  }

  // Called on each move of the slider: lower the resolution now, restore it 250 ms after the last move.
  moving() {
    if (this.motionScale >= 1) return;
    clearTimeout(this.still);
    this.still = setTimeout(() => { this.scale = 1; this.resize(); }, 250);
    if (this.scale !== this.motionScale) {
      this.scale = this.motionScale;
      this.resize();
    }
  }

  // Full resolution now (for reading the pixels).
  settle() {
    clearTimeout(this.still);
    if (this.scale !== 1) {
      this.scale = 1;
      this.resize();
    }
  }

  render(force = false) {
    if (!this.dirty && !force) return false;
    this.renderer.render(this.scene, this.camera);
    this.dirty = false;
    this.frames++;
    return true;
  }
}
