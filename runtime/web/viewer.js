// Loads a baked glTF and renders it once from one of its cameras, the way irview does (without a camera to
// ask for and none in the file, irview's overview: overview_camera.js).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { MozLightmapExtension } from './moz_lightmap.js';
import { IrbakeShadowmaskExtension } from './irbake_shadowmask.js';
import { IrbakeLightProbesExtension } from './irbake_light_probes.js';
import { IrbakeLightmapScenariosExtension } from './irbake_lightmap_scenarios.js';
import { addProbeObjects, lightProbeLitMeshes, lookAtCamera } from './probe_objects.js';
import { overviewCamera } from './overview_camera.js';

// lightmapMode: 'sh' (default) shades directional maps with the normal map, 'l0' shows the plain map.
// plugin false: plain GLTFLoader without our plugins (MOZ_lightmap, IRBAKE_light_probes), as a viewer that does not know them.
// mixedLights false: MOZ_lightmap only, every light removed (the map alone, as a client without irbake_shadowmask.js).
// probeObjects: [[x, y, z, r], ...] white spheres lit by IRBAKE_light_probes (probe_objects.js); view: { eye,
// target, fov } a look-at camera instead of glTF camera `camera`, as irview --eye/--target/--fov.
// camera null: the file's camera 0, or irview's overview of the scene when it has none (as irview without --camera).
// scenarios false: IRBAKE_lightmap_scenarios left unread (the document's own maps, its default scenario); else the
// layers blended at run time (irbake_lightmap_scenarios.js) from `scenario` (a stored one's name; null: the
// default) with `weights` ({ layer: w }, w one number or [r, g, b]) over it. The result's `controls` (null without
// layers) change the blend and render again: { layers, scenarios, weights(), setWeights(w), useScenario(name) }.
// exposure: display exposure in stops, as irview --exposure (2^EV × the linear colour, clamped, then sRGB; the sky
// behind the scene too).
export async function showBakedScene({ scene, camera = null, width, height, lightmapMode = 'sh', plugin = true,
                                       mixedLights = true, probeObjects = [], view = null, scenarios = true,
                                       scenario = null, weights = null, exposure = 0 }) {
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height);
  renderer.outputColorSpace = THREE.SRGBColorSpace;  // irview: exact sRGB encode, clamp, exposure 0
  renderer.toneMapping = exposure ? THREE.LinearToneMapping : THREE.NoToneMapping;  // Linear: saturate(exposure × c)
  renderer.toneMappingExposure = 2 ** exposure;
  document.body.appendChild(renderer.domElement);

  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder);  // EXT_meshopt_compression: gltf-transform optimize's default
  let lightmapExtension = null;
  let shadowmask = null;  // mixed lighting: the lights the bake left to the client, shadowed by the mask pages
  let layers = null;      // light groups' layers, blended at run time
  if (plugin) {
    loader.register(parser => (lightmapExtension = new MozLightmapExtension(parser, { lightmapMode })));
    loader.register(parser => new IrbakeLightProbesExtension(parser));
    if (mixedLights) loader.register(parser => (shadowmask = new IrbakeShadowmaskExtension(parser)));
    if (scenarios) loader.register(parser => (layers = new IrbakeLightmapScenariosExtension(parser, { scenario, weights })));
  }
  const gltf = await loader.loadAsync(scene);
  // The light maps hold the baked lights' light already: drop those; keep the ones the bake left to the client
  // (indirect and shadowmask modes), which three.js shades in real time.
  const lights = [];
  gltf.scene.traverse(o => { if (o.isLight && !shadowmask?.isRuntimeLight(o)) lights.push(o); });
  for (const l of lights) l.parent.remove(l);
  shadowmask?.syncLights(gltf.scene);
  gltf.scene.updateMatrixWorld(true);

  const overview = !view && camera === null && gltf.cameras.length === 0;
  const bounds = overview ? new THREE.Box3().setFromObject(gltf.scene, true) : null;  // before the probe spheres
  const probeLit = plugin ? lightProbeLitMeshes(gltf, scene) : 0;
  const probes = addProbeObjects(gltf, probeObjects, scene);
  const cam = view ? lookAtCamera(view) : overview ? overviewCamera(bounds) : gltf.cameras[camera ?? 0];
  if (!cam) throw new Error(`${scene}: no camera ${camera}: the file has ${gltf.cameras.length} (leave the camera out for the overview)`);
  cam.aspect = width / height;  // irview uses the viewport's aspect
  cam.updateProjectionMatrix();
  // Behind the scene the bake's uniform sky (root extras irbakeSky), as irview draws it; else black.
  const sky = gltf.parser.json.extras?.irbakeSky?.radiance;
  if (Array.isArray(sky) && sky.length === 3 && sky.every(Number.isFinite))
    renderer.setClearColor(new THREE.Color().setRGB(...sky.map(c => Math.min(c * 2 ** exposure, 1)), THREE.LinearSRGBColorSpace), 1);
  else
    renderer.setClearColor(0x000000, 1);
  renderer.render(gltf.scene, cam);
  const rerender = f => x => { f(x); renderer.render(gltf.scene, cam); };
  const controls = layers?.layers.length ? { layers: layers.layers, scenarios: layers.scenarios, weights: () => layers.weights(),
                                              setWeights: rerender(w => layers.setWeights(w)),
                                              useScenario: rerender(name => layers.useScenario(name)) } : null;
  return { width, height, overview, lights: lights.length, lightmapMode, plugin, controls,
           blendedMaterials: layers?.blendedMaterials ?? 0, weights: layers?.weights() ?? null,
           runtimeLights: shadowmask?.runtimeLights.length ?? 0, maskedMaterials: shadowmask?.maskedMaterials ?? 0,
           directionalMaterials: lightmapExtension?.directionalMaterials ?? 0,
           generatedTangents: lightmapExtension?.generatedTangents ?? 0, probes, probeLit };
}

export { canvasPixels } from './canvas_pixels.js';
