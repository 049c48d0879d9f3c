// The 3D view: the object's limit surface at the map's level, coloured per
// vertex, the sample sites as small spheres, the drag segments as lines laid
// on the surface, and a marker at the picked point. three.js, rendered on
// demand (after a change or a camera move), not in a loop.
//
// Contract:
//   const view = new SurfaceView(containerEl, { onPick(point) })
//   view.ok                 false when WebGL is unavailable (view.error says why)
//   view.setMesh(mesh)      mesh: { positions[], normals[], triangles[] } flat (api JSON form)
//   view.setColours(values, range)   per-vertex values -> viridis over range
//   view.setSamples(samples)         api sample forms (position, drag_direction, fit.friction.normal)
//   view.showPick(point, sample)     marker at the picked point; highlight a sample (or null)
//   view.stats()            { vertices, triangles, samples, frames }
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { viridis } from './colour_scale.js';

const CLICK_SLOP_PX = 4;  // a pointer that moved less than this between down and up is a click

export class SurfaceView {
  constructor(container, { onPick }) {
    this.container = container;
    this.onPick = onPick;
    this.frames = 0;
    this.vertexCount = 0;
    this.triangleCount = 0;
    this.sampleCount = 0;
    this.segmentCache = new Map();  // trace_id -> Float32Array of line points (laid on this mesh)
    this.ok = false;
    try {
      // preserveDrawingBuffer: the picture stays readable after a frame (screenshots, tests).
      this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    } catch (err) {
      this.error = `WebGL is not available: ${err.message}`;
      return;
    }
    this.ok = true;
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.domElement.classList.add('surface');
    container.prepend(this.renderer.domElement);

    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x0f1114);
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.1, 10000);
    this.camera.up.set(0, 0, 1);  // scenes are z-up (the bottle stands on z)
    this.scene.add(this.camera);
    // Mostly ambient so colours stay close to the legend; a head light shows the shape.
    this.scene.add(new THREE.AmbientLight(0xffffff, 1.5));
    const headLight = new THREE.DirectionalLight(0xffffff, 1.9);
    headLight.position.set(0.3, 0.4, 1);
    this.camera.add(headLight);

    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.requestRender());

    this.surface = null;
    this.sampleDots = null;
    this.segments = null;
    this.highlight = new THREE.Mesh(new THREE.SphereGeometry(1, 16, 12), new THREE.MeshBasicMaterial({ color: 0xff4d4d }));
    this.pickMarker = new THREE.Mesh(new THREE.SphereGeometry(1, 16, 12), new THREE.MeshBasicMaterial({ color: 0xffffff }));
    this.highlight.visible = false;
    this.pickMarker.visible = false;
    this.scene.add(this.highlight, this.pickMarker);
    this.showSamples = true;
    this.showSegments = true;

    new ResizeObserver(() => this.#resize()).observe(container);
    this.#resize();
    this.#listenForClicks();
  }

  setMesh(mesh) {
    if (!this.ok) return;
    if (this.surface) {
      this.scene.remove(this.surface);
      this.surface.geometry.dispose();
    }
    this.segmentCache.clear();
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(mesh.positions, 3));
    geometry.setAttribute('normal', new THREE.Float32BufferAttribute(mesh.normals, 3));
    const colours = new Float32Array(mesh.positions.length).fill(0.5);
    geometry.setAttribute('color', new THREE.Float32BufferAttribute(colours, 3));
    geometry.setIndex(mesh.triangles);
    geometry.computeBoundingSphere();
    const material = new THREE.MeshLambertMaterial({
      vertexColors: true,
      side: THREE.DoubleSide,
      // Push the surface back a little so lines laid on it win the depth test.
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    this.surface = new THREE.Mesh(geometry, material);
    this.scene.add(this.surface);
    this.positions = mesh.positions;
    this.normals = mesh.normals;
    this.vertexCount = mesh.positions.length / 3;
    this.triangleCount = mesh.triangles.length / 3;

    const sphere = geometry.boundingSphere;
    this.radius = sphere.radius;
    const markerSize = sphere.radius * 0.012;
    this.highlight.scale.setScalar(markerSize * 1.8);
    this.pickMarker.scale.setScalar(markerSize * 1.4);
    this.#frame(sphere);
    this.requestRender();
  }

  setColours(values, range) {
    if (!this.ok || !this.surface) return;
    const attr = this.surface.geometry.getAttribute('color');
    const colour = new THREE.Color();
    const n = Math.min(values.length, this.vertexCount);
    for (let i = 0; i < this.vertexCount; ++i) {
      const v = i < n ? values[i] : NaN;
      const t = range ? (v - range.min) / (range.max - range.min) : NaN;
      const [r, g, b] = viridis(t);
      colour.setRGB(r, g, b, THREE.SRGBColorSpace);  // legend colours are sRGB; three works in linear
      attr.setXYZ(i, colour.r, colour.g, colour.b);
    }
    attr.needsUpdate = true;
    this.requestRender();
  }

  setSamples(samples) {
    if (!this.ok || !this.surface) return;
    if (this.sampleDots) {
      this.scene.remove(this.sampleDots);
      this.sampleDots.geometry.dispose();
    }
    if (this.segments) {
      this.scene.remove(this.segments);
      this.segments.geometry.dispose();
    }
    this.samples = samples;
    this.sampleCount = samples.length;
    const dotGeometry = new THREE.SphereGeometry(this.radius * 0.008, 10, 8);
    this.sampleDots = new THREE.InstancedMesh(dotGeometry, new THREE.MeshBasicMaterial({ color: 0xf2f2f2 }), Math.max(1, samples.length));
    this.sampleDots.count = samples.length;
    const m = new THREE.Matrix4();
    samples.forEach((s, i) => {
      m.makeTranslation(s.position.x, s.position.y, s.position.z);
      this.sampleDots.setMatrixAt(i, m);
    });
    this.sampleDots.instanceMatrix.needsUpdate = true;
    this.sampleDots.visible = this.showSamples;
    this.scene.add(this.sampleDots);

    const points = [];
    for (const s of samples) {
      let line = this.segmentCache.get(s.trace_id);
      if (!line) {
        line = this.#segmentOnSurface(s);
        this.segmentCache.set(s.trace_id, line);
      }
      for (const v of line) points.push(v);
    }
    const segGeometry = new THREE.BufferGeometry();
    segGeometry.setAttribute('position', new THREE.Float32BufferAttribute(points, 3));
    this.segments = new THREE.LineSegments(segGeometry, new THREE.LineBasicMaterial({ color: 0x101010 }));
    this.segments.visible = this.showSegments;
    this.scene.add(this.segments);
    this.requestRender();
  }

  setOverlayVisibility({ samples, segments }) {
    this.showSamples = samples;
    this.showSegments = segments;
    if (this.sampleDots) this.sampleDots.visible = samples;
    if (this.segments) this.segments.visible = segments;
    this.requestRender();
  }

  showPick(point, sample) {
    if (!this.ok) return;
    this.pickMarker.visible = !!point;
    if (point) this.pickMarker.position.set(point.x, point.y, point.z);
    this.highlight.visible = !!sample;
    if (sample) this.highlight.position.set(sample.position.x, sample.position.y, sample.position.z);
    this.requestRender();
  }

  stats() {
    return { vertices: this.vertexCount, triangles: this.triangleCount, samples: this.sampleCount, frames: this.frames };
  }

  requestRender() {
    if (this.renderPending || !this.ok) return;
    this.renderPending = true;
    requestAnimationFrame(() => {
      this.renderPending = false;
      this.renderer.render(this.scene, this.camera);
      this.frames += 1;
      this.container.dataset.frames = String(this.frames);
    });
  }

  #resize() {
    const w = Math.max(1, this.container.clientWidth);
    const h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  // Look at the whole object from the front-left, a little from above.
  #frame(sphere) {
    const dir = new THREE.Vector3(-1, -0.55, 0.35).normalize();
    const distance = sphere.radius / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 1.05;
    this.camera.position.copy(sphere.center).addScaledVector(dir, distance);
    this.camera.near = distance / 100;
    this.camera.far = distance * 10;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(sphere.center);
    this.controls.update();
  }

  // The drag segment (centred on the site, along the drag direction) as a
  // polyline laid on the surface: each point is projected onto the tangent
  // plane of its nearest mesh vertex and lifted slightly, so the line follows
  // a curved object instead of cutting through it as a chord would.
  #segmentOnSurface(sample) {
    const P = this.positions;
    const N = this.normals;
    const c = sample.position;
    const d = sample.drag_direction;
    const half = sample.segment_length_mm / 2;
    const lift = this.radius * 0.002;
    // Vertices near the segment only (one pass over the mesh per sample).
    const reach2 = (half * 1.5 + this.radius * 0.05) ** 2;
    const near = [];
    for (let i = 0; i < P.length; i += 3) {
      const dx = P[i] - c.x; const dy = P[i + 1] - c.y; const dz = P[i + 2] - c.z;
      if (dx * dx + dy * dy + dz * dz <= reach2) near.push(i);
    }
    const steps = 12;
    const pts = [];
    for (let k = 0; k <= steps; ++k) {
      const s = -half + (2 * half * k) / steps;
      let x = c.x + d.x * s; let y = c.y + d.y * s; let z = c.z + d.z * s;
      let best = -1; let bestD = Infinity;
      for (const i of near) {
        const dx = P[i] - x; const dy = P[i + 1] - y; const dz = P[i + 2] - z;
        const dd = dx * dx + dy * dy + dz * dz;
        if (dd < bestD) { bestD = dd; best = i; }
      }
      if (best >= 0) {
        const off = (x - P[best]) * N[best] + (y - P[best + 1]) * N[best + 1] + (z - P[best + 2]) * N[best + 2];
        x += (lift - off) * N[best]; y += (lift - off) * N[best + 1]; z += (lift - off) * N[best + 2];
      }
      pts.push([x, y, z]);
    }
    const line = [];
    for (let k = 0; k < steps; ++k) line.push(...pts[k], ...pts[k + 1]);
    return line;
  }

  #listenForClicks() {
    const canvas = this.renderer.domElement;
    let down = null;
    canvas.addEventListener('pointerdown', (e) => { down = { x: e.clientX, y: e.clientY }; });
    canvas.addEventListener('pointerup', (e) => {
      if (!down || !this.surface) return;
      const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
      down = null;
      if (moved > CLICK_SLOP_PX) return;
      const rect = canvas.getBoundingClientRect();
      const ndc = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1, -((e.clientY - rect.top) / rect.height) * 2 + 1);
      const raycaster = new THREE.Raycaster();
      raycaster.setFromCamera(ndc, this.camera);
      const hit = raycaster.intersectObject(this.surface, false)[0];
      if (hit) this.onPick({ x: hit.point.x, y: hit.point.y, z: hit.point.z });
    });
  }
}
