// irview's overview camera (runtime/view_camera.cpp, overview): for a scene without cameras, a 45° view from
// outside the scene's bounds, turned 0.06 of a turn about +Y from +Z and raised 0.35 against the horizontal,
// far enough that the bounding sphere fills 1/1.15 of the view, looking at the bounds' centre.
import * as THREE from 'three';

// The same numbers as view_camera.cpp's orbit() at t = 0.06 and sceneNear().
const FOV_DEGREES = 45, TURN = 0.06, RISE = 0.35, MARGIN = 1.15;

// bounds: a THREE.Box3 of the scene's triangles in world space (irview: Scene::bounds()). Empty: the cube ±1.
export function overviewCamera(bounds, aspect = 1) {
  const b = bounds && !bounds.isEmpty() ? bounds : new THREE.Box3(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
  const centre = b.getCenter(new THREE.Vector3());
  const diagonal = b.getSize(new THREE.Vector3()).length();
  const radius = Math.max(0.5 * diagonal, 1e-3);
  const distance = MARGIN * radius / Math.sin(THREE.MathUtils.degToRad(FOV_DEGREES) * 0.5);
  const a = 2 * Math.PI * TURN;
  const eye = new THREE.Vector3(Math.sin(a), RISE, Math.cos(a)).normalize().multiplyScalar(distance).add(centre);
  const near = Math.max(1e-4, 1e-3 * Math.max(diagonal, 1e-3));
  // irview's projection has no far plane; three.js needs one: beyond the whole scene seen from the eye.
  const cam = new THREE.PerspectiveCamera(FOV_DEGREES, aspect, near, 4 * (distance + radius));
  cam.position.copy(eye);
  const dir = centre.clone().sub(eye).normalize();
  if (Math.abs(dir.y) > 0.999) cam.up.set(0, 0, -1);  // looking straight down or up, as irview
  cam.lookAt(centre);
  cam.updateMatrixWorld(true);
  return cam;
}
