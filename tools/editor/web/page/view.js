// The 3D view: the two sides' surfaces and the in-between (coloured by the timing's delay), the
// feature elements, the timing's sweep, the camera of the scene's shot (orbit from there), the
// gizmo, picking and snapping.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/OrbitControls.js';
import { TransformControls } from 'three/addons/TransformControls.js';
import { COLORS, makeElement, placeElement, interpolate, keepMarkerSize, highlight } from './features.js';
import { SweepView, delayColors } from './timing.js';

/** Whether WebGL runs on the CPU (SwiftShader, llvmpipe): then no multisampling, which would cost
 * it several times the drawing. */
function softwareRendering() {
  const gl = document.createElement('canvas').getContext('webgl2');
  if (!gl) return false;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  gl.getExtension('WEBGL_lose_context')?.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
}

export class View {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: !softwareRendering(), preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.renderer.setClearColor(0x16171a);
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x404048, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.8);
    sun.position.set(1, 2, 1.5);
    this.scene.add(sun);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
    this.orbit = new OrbitControls(this.camera, this.renderer.domElement);
    this.orbit.addEventListener('change', () => this.render());
    this.gizmo = new TransformControls(this.camera, this.renderer.domElement);
    this.gizmo.addEventListener('change', () => this.render());
    this.gizmo.addEventListener('dragging-changed', (e) => { this.orbit.enabled = !e.value; });
    this.scene.add(this.gizmo.getHelper ? this.gizmo.getHelper() : this.gizmo);
    this.surfaces = {};
    this.pairs = []; // [{source, target, at}] groups
    this.sweep = new SweepView(this.scene);
    this.timing = null; // the state's
    this.delayShown = true;
    this.afterRender = [];
    new ResizeObserver(() => this.resize()).observe(container);
  }

  /** The shot's camera: eye, look-at, up and the horizontal field of view (degrees). */
  setCamera(c) {
    this.hfov = c.fov;
    this.camera.position.set(...c.eye);
    this.camera.up.set(...c.up);
    this.orbit.target.set(...c.lookat);
    this.resize();
    this.orbit.update();
  }

  resize() {
    const w = this.container.clientWidth, h = this.container.clientHeight;
    if (!w || !h) return;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    const half = THREE.MathUtils.degToRad(this.hfov || 40) / 2;
    this.camera.fov = THREE.MathUtils.radToDeg(2 * Math.atan(Math.tan(half) / this.camera.aspect));
    this.camera.updateProjectionMatrix();
    this.render();
  }

  /** Replaces the surface `name` ('source', 'target' or 'morph'). */
  setSurface(name, geometry) {
    const style = {
      source: { color: COLORS.source, opacity: 0.22 },
      target: { color: COLORS.target, opacity: 0.22 },
      morph: { color: 0xc8c2b8, opacity: 1.0 },
    }[name];
    const old = this.surfaces[name];
    const material = new THREE.MeshStandardMaterial({
      color: style.color, roughness: 0.7, transparent: style.opacity < 1, opacity: style.opacity,
      depthWrite: style.opacity === 1, side: THREE.DoubleSide });
    const mesh = new THREE.Mesh(geometry, material);
    mesh.visible = old ? old.visible : true;
    mesh.renderOrder = style.opacity < 1 ? 1 : 0;
    mesh.userData.color = style.color;
    if (old) { this.scene.remove(old); old.geometry.dispose(); old.material.dispose(); }
    this.surfaces[name] = mesh;
    this.scene.add(mesh);
    if (name === 'morph') this.colorByDelay();
    this.render();
  }

  /** The in-between coloured by each vertex's delay when the scene has a timing and the colours
   * are shown; its plain colour otherwise. */
  colorByDelay() {
    const mesh = this.surfaces.morph;
    if (!mesh) return;
    const delays = mesh.geometry.userData.delays, spread = this.timing ? this.timing.spread : 0;
    const on = this.delayShown && delays && spread > 0;
    if (on) mesh.geometry.setAttribute('color', new THREE.BufferAttribute(delayColors(delays, spread), 3));
    mesh.material.vertexColors = Boolean(on);
    mesh.material.color.setHex(on ? 0xffffff : mesh.userData.color);
    mesh.material.needsUpdate = true;
    this.render();
  }

  showDelay(on) {
    this.delayShown = on;
    this.colorByDelay();
  }

  /** The state's timing: the delay's colours over [0, spread] and the sweep, if any. */
  setTiming(timing) {
    this.timing = timing;
    const box = new THREE.Box3();
    for (const name of ['source', 'target']) if (this.surfaces[name]) box.expandByObject(this.surfaces[name]);
    const half = box.isEmpty() ? 1 : 0.35 * box.getSize(new THREE.Vector3()).length();
    this.sweep.set(timing && timing.spread > 0 ? timing.sweep : null, half, 1.6 * this.markerSize());
    this.colorByDelay();
  }

  /** Attaches the gizmo to the sweep's handle `which` ('origin' or 'end'), the pairs unselected. */
  selectSweep(which) {
    this.pairs.forEach((p) => { for (const s of ['source', 'target']) highlight(p[s], false); });
    const handle = this.sweep.handles.find((h) => h.userData.pick.sweep === which);
    if (handle) this.gizmo.attach(handle); else this.gizmo.detach();
    this.render();
  }

  showSurface(name, on) {
    if (this.surfaces[name]) this.surfaces[name].visible = on;
    this.render();
  }

  /** Surface `name`'s bounding box: its centre and size, world units. */
  surfaceBox(name) {
    const box = this.surfaces[name].geometry.boundingBox;
    return { centre: box.getCenter(new THREE.Vector3()).toArray(), size: box.getSize(new THREE.Vector3()).toArray() };
  }

  /** World units for an origin's marker: a hundredth of the sides' size. */
  markerSize() {
    const box = new THREE.Box3();
    for (const name of ['source', 'target']) if (this.surfaces[name]) box.expandByObject(this.surfaces[name]);
    return box.isEmpty() ? 0.01 : box.getSize(new THREE.Vector3()).length() / 120;
  }

  /** Draws `pairs` (the state's) at t, pair `selected` (from 1) highlighted on its `side`. */
  setPairs(pairs, t, selected, side) {
    this.gizmo.detach();
    for (const p of this.pairs) for (const g of Object.values(p)) this.scene.remove(g);
    const size = this.markerSize();
    this.pairs = pairs.map((pair, i) => {
      const drawn = {};
      for (const s of ['source', 'target']) {
        drawn[s] = makeElement(pair.type, COLORS[s], size);
        placeElement(drawn[s], pair[s]);
        drawn[s].userData.pick = { pair: i + 1, side: s };
      }
      drawn.at = makeElement(pair.type, COLORS.at, size * 1.2);
      placeElement(drawn.at, interpolate(pair.source, pair.target, t));
      for (const g of Object.values(drawn)) this.scene.add(g);
      return drawn;
    });
    this.select(selected, side);
  }

  /** Moves the amber elements to t. */
  setTime(pairs, t) {
    pairs.forEach((pair, i) => placeElement(this.pairs[i].at, interpolate(pair.source, pair.target, t)));
    this.render();
  }

  select(selected, side) {
    this.pairs.forEach((p, i) => {
      for (const s of ['source', 'target']) highlight(p[s], i + 1 === selected && s === side);
    });
    const drawn = this.pairs[selected - 1];
    if (drawn) this.gizmo.attach(drawn[side]); else this.gizmo.detach();
    this.render();
  }

  /** The element ({pair, side}) or the sweep's handle ({sweep}) under a pointer event, if any. */
  pick(event) {
    const ray = this.rayAt(event);
    ray.params.Line.threshold = this.markerSize();
    // The sweep's handles first: small, and often on an element's outline (an edge's pick reaches
    // a marker's size from the line).
    const handle = ray.intersectObjects(this.sweep.handles, false)[0];
    if (handle) return handle.object.userData.pick;
    const objects = this.pairs.flatMap((p) => [p.source, p.target]);
    for (const hit of ray.intersectObjects(objects, true)) {
      let o = hit.object;
      while (o && !o.userData.pick) o = o.parent;
      if (o) return o.userData.pick;
    }
    return null;
  }

  /** The point of side `name`'s surface under a pointer event, or null. */
  surfacePoint(event, name) {
    const mesh = this.surfaces[name];
    if (!mesh) return null;
    const hit = this.rayAt(event).intersectObject(mesh, false)[0];
    return hit ? hit.point : null;
  }

  rayAt(event) {
    const r = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - r.left) / r.width) * 2 - 1, -((event.clientY - r.top) / r.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    return ray;
  }

  /** Page coordinates (CSS pixels) of a world point. */
  toScreen(point) {
    const v = new THREE.Vector3(...point).project(this.camera);
    const r = this.renderer.domElement.getBoundingClientRect();
    return { x: r.left + ((v.x + 1) / 2) * r.width, y: r.top + ((1 - v.y) / 2) * r.height, visible: v.z < 1 };
  }

  /** Redraws at the next animation frame, once however many changes asked for it. */
  render() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => this.renderNow());
  }

  /** Redraws now; then the callbacks waiting for a redraw. */
  renderNow() {
    this.pending = false;
    for (const p of this.pairs) for (const g of Object.values(p)) keepMarkerSize(g);
    this.renderer.render(this.scene, this.camera);
    for (const f of this.afterRender.splice(0)) f();
  }

  /** Resolves once the view has been redrawn with what it holds now. */
  drawn() {
    return new Promise((done) => { this.afterRender.push(done); this.render(); });
  }
}
