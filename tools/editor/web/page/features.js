// Feature elements drawn as `volmorph preview` draws them (tools/PreviewCommand.cpp): amber at t,
// blue on the source side, pink on the target side. An element is a Group placed at its origin,
// turned by its frame and scaled by its scale, so that a gizmo moving, turning or scaling the
// group edits the element's origin, axes or scale directly (libvolmorph/include/volmorph/Feature.h:
// a segment is scale.x long along x, a rectangle scale.x by scale.y, a box scale.x by y by z, all
// centred on the origin).
import * as THREE from 'three';

export const COLORS = { at: 0xffbf0d, source: 0x0d99ff, target: 0xff1a99, selected: 0xffffff };

const box = [
  [-1, -1, -1], [1, -1, -1], [1, -1, -1], [1, 1, -1], [1, 1, -1], [-1, 1, -1], [-1, 1, -1], [-1, -1, -1],
  [-1, -1, 1], [1, -1, 1], [1, -1, 1], [1, 1, 1], [1, 1, 1], [-1, 1, 1], [-1, 1, 1], [-1, -1, 1],
  [-1, -1, -1], [-1, -1, 1], [1, -1, -1], [1, -1, 1], [1, 1, -1], [1, 1, 1], [-1, 1, -1], [-1, 1, 1],
];
const OUTLINES = {
  point: [],
  segment: [[-1, 0, 0], [1, 0, 0]],
  rectangle: [[-1, -1, 0], [1, -1, 0], [1, -1, 0], [1, 1, 0], [1, 1, 0], [-1, 1, 0], [-1, 1, 0], [-1, -1, 0]],
  box,
};

/** The frame's rotation: rows x, y, z of the element are the columns of the rotation matrix. */
export function frameQuaternion(axes) {
  const x = new THREE.Vector3(...axes[0]).normalize();
  const y = new THREE.Vector3(...axes[1]);
  y.addScaledVector(x, -y.dot(x)).normalize();
  const z = new THREE.Vector3().crossVectors(x, y);
  return new THREE.Quaternion().setFromRotationMatrix(new THREE.Matrix4().makeBasis(x, y, z));
}

/** The element at t: origin and scale linear, the frame by slerp along the shorter arc. */
export function interpolate(a, b, t) {
  const lerp = (u, v) => u.map((value, i) => value + t * (v[i] - value));
  const q = frameQuaternion(a.axes).slerp(frameQuaternion(b.axes), t);
  const m = new THREE.Matrix4().makeRotationFromQuaternion(q);
  const x = new THREE.Vector3(), y = new THREE.Vector3(), z = new THREE.Vector3();
  m.extractBasis(x, y, z);
  return { origin: lerp(a.origin, b.origin), axes: [x.toArray(), y.toArray()], scale: lerp(a.scale, b.scale) };
}

/** A drawn element: `markerSize` world units for its origin's marker, whatever its scale. */
export function makeElement(type, color, markerSize) {
  const group = new THREE.Group();
  const material = new THREE.LineBasicMaterial({ color, depthTest: false, transparent: true });
  const points = OUTLINES[type].map((p) => new THREE.Vector3(p[0] / 2, p[1] / 2, p[2] / 2));
  if (points.length) {
    const outline = new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(points), material);
    outline.renderOrder = 10;
    group.add(outline);
  }
  const marker = new THREE.Mesh(
    new THREE.OctahedronGeometry(markerSize * (type === 'point' ? 1.0 : 0.6)),
    new THREE.MeshBasicMaterial({ color, depthTest: false, transparent: true }));
  marker.renderOrder = 11;
  group.add(marker);
  group.userData = { type, marker, materials: [material, marker.material], color };
  return group;
}

/** Places `group` as `element` ({origin, axes, scale}). */
export function placeElement(group, element) {
  group.position.set(...element.origin);
  group.quaternion.copy(frameQuaternion(element.axes));
  group.scale.set(...element.scale);
  keepMarkerSize(group);
}

/** The marker keeps its size in world units while the group is scaled. */
export function keepMarkerSize(group) {
  const s = group.scale;
  group.userData.marker.scale.set(1 / Math.max(s.x, 1e-6), 1 / Math.max(s.y, 1e-6), 1 / Math.max(s.z, 1e-6));
}

/** A number as the scene writes it: to 1e-4 (SceneDocument's tomlRounded), never -0. */
export const round4 = (v) => Math.round(v * 1e4) / 1e4 + 0;

/** The element a placed group stands for, rounded as the scene writes numbers. */
export function elementOf(group) {
  const x = new THREE.Vector3(1, 0, 0).applyQuaternion(group.quaternion);
  const y = new THREE.Vector3(0, 1, 0).applyQuaternion(group.quaternion);
  return {
    origin: group.position.toArray().map(round4),
    axes: [x.toArray().map(round4), y.toArray().map(round4)],
    scale: group.scale.toArray().map((v) => Math.max(round4(Math.abs(v)), 1e-4)),
  };
}

export function highlight(group, on) {
  for (const m of group.userData.materials) m.color.setHex(on ? COLORS.selected : group.userData.color);
}
