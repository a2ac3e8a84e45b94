// The scene's [timing] in the view (issue 59): the in-between coloured by each place's delay (the
// server sends it per vertex: blue starts first, red last, over [0, spread]), and the sweep as
// `volmorph preview` thinks of it: its start plane through the origin, its end plane `length`
// along the direction, an arrow between them, and two handles for the gizmo: the start moves the
// origin (the direction and length kept), the end turns the direction and sets the length.
import * as THREE from 'three';

export const DELAY_COLORS = { early: 0x2c7bb6, middle: 0xf4efd8, late: 0xd7191c };

/** Linear RGB per vertex from its delay in t: early blue through pale to late red over [0, spread]. */
export function delayColors(delays, spread) {
  const early = new THREE.Color(DELAY_COLORS.early), middle = new THREE.Color(DELAY_COLORS.middle);
  const late = new THREE.Color(DELAY_COLORS.late), c = new THREE.Color();
  const colors = new Float32Array(3 * delays.length);
  for (let i = 0; i < delays.length; ++i) {
    const u = spread > 0 ? Math.min(Math.max(delays[i] / spread, 0), 1) : 0;
    if (u < 0.5) c.lerpColors(early, middle, 2 * u); else c.lerpColors(middle, late, 2 * u - 1);
    c.toArray(colors, 3 * i);
  }
  return colors;
}

/** A square plane `half` world units from its centre to each side, facing `direction`. */
function makePlane(color, half) {
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(2 * half, 2 * half),
    new THREE.MeshBasicMaterial({ color, transparent: true, opacity: 0.14, side: THREE.DoubleSide, depthWrite: false }));
  const edge = new THREE.LineSegments(new THREE.EdgesGeometry(plane.geometry),
    new THREE.LineBasicMaterial({ color, transparent: true, opacity: 0.8 }));
  plane.add(edge);
  plane.renderOrder = 2;
  return plane;
}

function makeHandle(color, size, which) {
  const handle = new THREE.Mesh(new THREE.SphereGeometry(size, 16, 12),
    new THREE.MeshBasicMaterial({ color, depthTest: false, transparent: true }));
  handle.renderOrder = 12;
  handle.userData.pick = { sweep: which };
  return handle;
}

export class SweepView {
  constructor(scene) {
    this.scene = scene;
    this.group = new THREE.Group();
    scene.add(this.group);
    this.sweep = null;
  }

  /** Draws `sweep` ({origin, direction, length}, or null for none); planes `half` world units
   * across from their centres, handles `size` world units. */
  set(sweep, half, size) {
    for (const child of [...this.group.children]) this.group.remove(child);
    this.sweep = sweep;
    this.handles = [];
    if (!sweep) return;
    this.start = makePlane(DELAY_COLORS.early, half);
    this.end = makePlane(DELAY_COLORS.late, half);
    this.arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 1, 0), new THREE.Vector3(), 1, 0xdddddd);
    this.startHandle = makeHandle(DELAY_COLORS.early, size, 'origin');
    this.endHandle = makeHandle(DELAY_COLORS.late, size, 'end');
    this.handles = [this.startHandle, this.endHandle];
    this.group.add(this.start, this.end, this.arrow, this.startHandle, this.endHandle);
    const origin = new THREE.Vector3(...sweep.origin);
    this.startHandle.position.copy(origin);
    this.endHandle.position.copy(origin).addScaledVector(new THREE.Vector3(...sweep.direction), sweep.length);
    this.place();
  }

  /** The planes and the arrow between the two handles where they are now. */
  place() {
    const a = this.startHandle.position, b = this.endHandle.position;
    const along = new THREE.Vector3().subVectors(b, a);
    const length = Math.max(along.length(), 1e-6);
    const direction = along.clone().divideScalar(length);
    const facing = new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 0, 1), direction);
    this.start.position.copy(a);
    this.end.position.copy(b);
    this.start.quaternion.copy(facing);
    this.end.quaternion.copy(facing);
    this.arrow.position.copy(a);
    this.arrow.setDirection(direction);
    this.arrow.setLength(length, Math.min(0.2 * length, 0.08), Math.min(0.1 * length, 0.04));
  }

  /** While a handle is dragged: the start carries the end with it; the end turns the sweep. */
  follow(handle) {
    if (handle === this.startHandle) {
      const s = this.sweep;
      this.endHandle.position.copy(handle.position).addScaledVector(new THREE.Vector3(...s.direction), s.length);
    }
    this.place();
  }

  /** The scene keys a dragged handle sets ({key: value}), rounded as the scene writes numbers;
   * null when it did not move. */
  edited(handle, round) {
    if (handle === this.startHandle) {
      const origin = handle.position.toArray().map(round);
      return origin.every((v, i) => v === round(this.sweep.origin[i])) ? null : { 'timing.sweep.origin': origin };
    }
    const along = new THREE.Vector3().subVectors(this.endHandle.position, this.startHandle.position);
    const length = round(along.length());
    if (!(length > 0)) return null;
    const direction = along.normalize().toArray().map(round);
    const same = length === round(this.sweep.length) && direction.every((v, i) => v === round(this.sweep.direction[i]));
    return same ? null : { 'timing.sweep.direction': direction, 'timing.sweep.length': length };
  }
}
