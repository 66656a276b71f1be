// Loads a baked glTF and renders it once from one of its cameras, the way irview does.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { MozLightmapExtension } from './moz_lightmap.js';

// lightmapMode: 'sh' (default) shades directional maps with the normal map, 'l0' shows the plain map.
export async function showBakedScene({ scene, camera = 0, width, height, lightmapMode = 'sh' }) {
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height);
  renderer.outputColorSpace = THREE.SRGBColorSpace;  // irview: exact sRGB encode, clamp, exposure 0
  renderer.toneMapping = THREE.NoToneMapping;
  document.body.appendChild(renderer.domElement);

  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder);  // EXT_meshopt_compression: gltf-transform optimize's default
  let lightmapExtension = null;
  loader.register(parser => (lightmapExtension = new MozLightmapExtension(parser, { lightmapMode })));
  const gltf = await loader.loadAsync(scene);
  // The light maps hold the punctual lights' light already: drop the lights GLTFLoader made.
  const lights = [];
  gltf.scene.traverse(o => { if (o.isLight) lights.push(o); });
  for (const l of lights) l.parent.remove(l);
  gltf.scene.updateMatrixWorld(true);

  const cam = gltf.cameras[camera];
  if (!cam) throw new Error(`${scene}: no camera ${camera}`);
  cam.aspect = width / height;  // irview uses the viewport's aspect
  cam.updateProjectionMatrix();
  renderer.setClearColor(0x000000, 1);
  renderer.render(gltf.scene, cam);
  return { width, height, lights: lights.length, lightmapMode, directionalMaterials: lightmapExtension.directionalMaterials,
           generatedTangents: lightmapExtension.generatedTangents };
}

// RGBA bytes of the canvas, top row first (as a PNG), for comparisons.
export function canvasPixels() {
  const canvas = document.querySelector('canvas');
  const gl = canvas.getContext('webgl2');
  const w = canvas.width, h = canvas.height;
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const flipped = new Uint8Array(px.length);
  for (let y = 0; y < h; ++y) flipped.set(px.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
  return flipped;
}
