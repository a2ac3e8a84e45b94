// The editor's JSON API (tools/editor/EditorSession.h), with the session's cookie (EditorServer.h), and the
// compact meshes it sends (EditorSession.h, encodeMesh).
import * as THREE from 'three';

async function call(method, route, body) {
  const response = await fetch(route, {
    method,
    headers: { 'Content-Type': 'application/json' },
    credentials: 'same-origin', // the session's cookie, set when the printed URL was opened
    body: body === undefined ? undefined : JSON.stringify(body),
  });
  if (!response.ok) {
    let message = `${response.status}`;
    try { message = (await response.json()).error || message; } catch (e) { /* not JSON */ }
    throw new Error(message);
  }
  return response;
}

export async function getState() { return (await call('GET', '/api/state')).json(); }

/** An edit: 'set', 'add', 'duplicate', 'delete', 'undo', 'redo', 'suggest' or 'save'. */
export async function post(action, body = {}) {
  return (await call('POST', `/api/${action}`, body)).json();
}

/** "VMM1", counts, the box, uint16 positions over the box, padding, uint32 triangles; "VMM2" adds
 * each vertex's delay under the scene's timing (float32, in t): geometry.userData.delays. */
export function decodeMesh(buffer) {
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== 'VMM1' && magic !== 'VMM2') throw new Error('not a volmorph mesh');
  const vertices = view.getUint32(4, true), triangles = view.getUint32(8, true);
  const lo = [0, 1, 2].map((i) => view.getFloat32(12 + 4 * i, true));
  const hi = [0, 1, 2].map((i) => view.getFloat32(24 + 4 * i, true));
  const quantized = new Uint16Array(buffer, 36, 3 * vertices);
  const positions = new Float32Array(3 * vertices);
  for (let i = 0; i < 3 * vertices; ++i) {
    const axis = i % 3;
    positions[i] = lo[axis] + (quantized[i] / 65535) * (hi[axis] - lo[axis]);
  }
  const indexStart = (36 + 6 * vertices + 3) & ~3;
  const indices = new Uint32Array(buffer, indexStart, 3 * triangles);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setIndex(new THREE.BufferAttribute(indices, 1));
  if (magic === 'VMM2') geometry.userData.delays = new Float32Array(buffer, indexStart + 12 * triangles, vertices);
  geometry.computeVertexNormals();
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  return geometry;
}

/** The surface of 'source', 'target', or the in-between ('morph') at t. */
export async function getMesh(of, t = 0.5) {
  const query = of === 'morph' ? `of=morph&t=${t}` : `of=${of}`;
  return decodeMesh(await (await call('GET', `/api/mesh?${query}`)).arrayBuffer());
}
