// MOZ_lightmap read from its specification alone (KhronosGroup/glTF, extensions/2.0/Vendor/MOZ_lightmap), as any
// three.js application would read it, with none of irbake's plugins: plain GLTFLoader, then for every material
// whose glTF definition carries the extension,
//   material.lightMap = the texture `index` (sRGB, as the specification requires), read through TEXCOORD_<texCoord>
//   (default 1: lightMap.channel), and material.lightMapIntensity = intensity (default 1),
// since three.js takes lightMap × lightMapIntensity as the irradiance E and shades it with the Lambert BRDF
// (c_diff / π) × E, the specification's formula. Materials with KHR_materials_unlit follow its unlit rule,
// colour = baseColor × lightmapLinear × intensity: three.js's MeshBasicMaterial divides its light map by π, so its
// intensity is intensity × π (the specification's implementation note). The lights are removed (the bake holds
// the total light, and the specification's "Baked and Dynamic Lights" keeps baked lights off light-mapped
// surfaces); occlusionTexture stays as GLTFLoader sets it (aoMap), which three.js applies to the light map.
// Options: standard false shades the light-mapped PBR materials with three.js's Lambert material (the
// specification's formula without the Fresnel weight on the diffuse lobe that MeshStandardMaterial applies).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const NAME = 'MOZ_lightmap';

// Sets the light maps of a loaded glTF `gltf` from its MOZ_lightmap extensions; returns how many materials got one.
export async function applySpecLightmaps(gltf, { standard = true } = {}) {
  const parser = gltf.parser, defs = parser.json.materials ?? [];
  const meshes = [];
  gltf.scene.traverse(o => { if (o.isMesh) meshes.push(o); });
  const done = new Map();  // three material → its light-mapped replacement
  for (const mesh of meshes) {
    const index = parser.associations.get(mesh.material)?.materials;
    const ext = index === undefined ? undefined : defs[index]?.extensions?.[NAME];
    if (!ext) continue;
    if (!done.has(mesh.material)) {
      const texture = (await parser.getDependency('texture', ext.index)).clone();
      texture.colorSpace = THREE.SRGBColorSpace;
      texture.channel = ext.texCoord ?? 1;
      const intensity = ext.intensity ?? 1;
      let material = mesh.material;
      const unlit = defs[index].extensions?.KHR_materials_unlit !== undefined;
      if (!unlit && !standard) material = lambertOf(material);
      material.lightMap = texture;
      material.lightMapIntensity = unlit ? intensity * Math.PI : intensity;
      material.needsUpdate = true;
      done.set(mesh.material, material);
    }
    mesh.material = done.get(mesh.material);
  }
  return done.size;
}

function lambertOf(m) {
  const l = new THREE.MeshLambertMaterial();
  for (const key of ['name', 'color', 'map', 'emissive', 'emissiveMap', 'emissiveIntensity', 'aoMap', 'aoMapIntensity',
                     'opacity', 'transparent', 'alphaTest', 'side', 'vertexColors', 'normalMap', 'normalScale'])
    if (m[key] !== undefined) l[key] = m[key]?.clone && !m[key].isTexture ? m[key].clone() : m[key];
  return l;
}

// Loads `scene` and renders it once from glTF camera `camera` at width × height, sRGB output, no tone mapping.
export async function showSpecScene({ scene, camera = 0, width, height, standard = true }) {
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height);
  renderer.outputColorSpace = THREE.SRGBColorSpace;
  renderer.toneMapping = THREE.NoToneMapping;
  document.body.appendChild(renderer.domElement);
  const gltf = await new GLTFLoader().loadAsync(scene);
  const lights = [];
  gltf.scene.traverse(o => { if (o.isLight) lights.push(o); });
  for (const l of lights) l.parent.remove(l);
  const lightmapped = await applySpecLightmaps(gltf, { standard });
  gltf.scene.updateMatrixWorld(true);
  const cam = gltf.cameras[camera];
  if (!cam) throw new Error(`${scene}: no camera ${camera}`);
  cam.aspect = width / height;
  cam.updateProjectionMatrix();
  // The backdrop: the bake's uniform sky (root extras irbakeSky), as irview draws it behind the scene; else black.
  const sky = gltf.parser.json.extras?.irbakeSky?.radiance;
  if (Array.isArray(sky) && sky.length === 3 && sky.every(Number.isFinite))
    renderer.setClearColor(new THREE.Color().setRGB(...sky, THREE.LinearSRGBColorSpace), 1);
  else
    renderer.setClearColor(0x000000, 1);
  renderer.render(gltf.scene, cam);
  return { width, height, lightmapped, standard, lights: lights.length };
}

export { canvasPixels } from './canvas_pixels.js';
