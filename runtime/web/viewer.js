// Loads a baked glTF and renders it once from one of its cameras, the way irview does.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { MozLightmapExtension } from './moz_lightmap.js';
import { IrbakeLightProbesExtension } from './irbake_light_probes.js';
import { addProbeObjects, lookAtCamera } from './probe_objects.js';

// lightmapMode: 'sh' (default) shades directional maps with the normal map, 'l0' shows the plain map.
// plugin false: plain GLTFLoader without our plugins (MOZ_lightmap, IRBAKE_light_probes), as a viewer that does not know them.
// probeObjects: [[x, y, z, r], ...] white spheres lit by IRBAKE_light_probes (probe_objects.js); view: { eye,
// target, fov } a look-at camera instead of glTF camera `camera`, as irview --eye/--target/--fov.
export async function showBakedScene({ scene, camera = 0, width, height, lightmapMode = 'sh', plugin = true,
                                       probeObjects = [], view = null }) {
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height);
  renderer.outputColorSpace = THREE.SRGBColorSpace;  // irview: exact sRGB encode, clamp, exposure 0
  renderer.toneMapping = THREE.NoToneMapping;
  document.body.appendChild(renderer.domElement);

  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder);  // EXT_meshopt_compression: gltf-transform optimize's default
  let lightmapExtension = null;
  if (plugin) loader.register(parser => (lightmapExtension = new MozLightmapExtension(parser, { lightmapMode })));
  if (plugin) loader.register(parser => new IrbakeLightProbesExtension(parser));
  const gltf = await loader.loadAsync(scene);
  // The light maps hold the punctual lights' light already: drop the lights GLTFLoader made.
  const lights = [];
  gltf.scene.traverse(o => { if (o.isLight) lights.push(o); });
  for (const l of lights) l.parent.remove(l);
  gltf.scene.updateMatrixWorld(true);

  const probes = addProbeObjects(gltf, probeObjects, scene);
  const cam = view ? lookAtCamera(view) : gltf.cameras[camera];
  if (!cam) throw new Error(`${scene}: no camera ${camera}`);
  cam.aspect = width / height;  // irview uses the viewport's aspect
  cam.updateProjectionMatrix();
  renderer.setClearColor(0x000000, 1);
  renderer.render(gltf.scene, cam);
  return { width, height, lights: lights.length, lightmapMode, plugin,
           directionalMaterials: lightmapExtension?.directionalMaterials ?? 0,
           generatedTangents: lightmapExtension?.generatedTangents ?? 0, probes };
}

export { canvasPixels } from './canvas_pixels.js';
