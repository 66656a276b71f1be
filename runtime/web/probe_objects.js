// The viewer page's dynamic objects: matte white spheres (albedo 1, Lambert) lit by the scene's
// IRBAKE_light_probes (irbake_light_probes.js), as irview --probe-object X,Y,Z,R; and the look-at camera of
// irview --eye/--target/--fov.
import * as THREE from 'three';

// Adds one sphere per [x, y, z, r] to gltf.scene, each lit by the probes' field over it (blend and gradient). Returns what each blended
// ({ probes, weight }). Throws naming the scene when it has no probes.
export function addProbeObjects(gltf, objects, sceneName) {
  if (!objects.length) return [];
  const grid = gltf.userData?.irbakeLightProbes;
  if (!grid) throw new Error(`${sceneName}: no IRBAKE_light_probes extension (baked with --probes off?)`);
  return objects.map(([x, y, z, r]) => {
    // Fine enough that the tessellation's normals stay within 0.1° of the sphere's (what a pixel shows).
    const mesh = new THREE.Mesh(new THREE.SphereGeometry(r, 256, 128),
                                new THREE.MeshLambertMaterial({ color: new THREE.Color(1, 1, 1) }));
    mesh.position.set(x, y, z);
    gltf.scene.add(mesh);
    const { probes, weight } = grid.lightObject(mesh, [x, y, z], r);
    return { probes, weight };
  });
}

// Probe-lit objects (extras.irbake.mode "probes" in the source; the export marks their primitives with
// extras.lightProbes, docs/export.md): each such mesh is lit by the probes over its bounding sphere
// (IrbakeProbeGrid.lightObject), as irview does. Without probes in the file they keep their material, with a
// warning. Returns how many meshes were lit.
export function lightProbeLitMeshes(gltf, sceneName) {
  const json = gltf.parser.json;
  const meshes = [];
  gltf.scene.traverse(o => {
    if (!o.isMesh) return;
    const source = gltf.parser.associations.get(o);
    const prim = source && json.meshes?.[source.meshes]?.primitives?.[source.primitives ?? 0];
    if (prim?.extras?.lightProbes === true) meshes.push(o);
  });
  const grid = gltf.userData?.irbakeLightProbes;
  if (meshes.length && !grid) {
    console.warn(`${sceneName}: ${meshes.length} probe-lit object(s) but no IRBAKE_light_probes: drawn without light`);
    return 0;
  }
  for (const mesh of meshes) grid.lightObject(mesh);
  return meshes.length;
}

// A perspective camera at `eye` looking at `target` (+Y up), vertical fov in degrees.
export function lookAtCamera({ eye, target, fov, aspect = 1 }) {
  const cam = new THREE.PerspectiveCamera(fov, aspect, 0.01, 1000);
  cam.position.set(...eye);
  cam.lookAt(new THREE.Vector3(...target));
  cam.updateMatrixWorld(true);
  return cam;
}

// "x,y,z[,r]" (r default 0.1 m, as irview) → [x, y, z, r]; throws for anything else.
export function parseProbeObject(text) {
  const v = text.split(',').map(Number);
  if ((v.length !== 3 && v.length !== 4) || !v.every(Number.isFinite)) throw new Error(`probeObject '${text}': X,Y,Z[,R]`);
  if (v.length === 3) v.push(0.1);
  if (!(v[3] > 0)) throw new Error(`probeObject '${text}': the radius must be positive`);
  return v;
}
