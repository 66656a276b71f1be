// Loads a baked glTF into Babylon.js and renders it once from one of its cameras, shaded as irview shades
// it: baseColour × light map + emissive (babylon_moz_lightmap.js), no scene lights, exact sRGB output, no tone
// mapping. plugin false: Babylon's loader alone, as an application that does not know MOZ_lightmap.
import { Engine } from '@babylonjs/core/Engines/engine.js';
import { Scene } from '@babylonjs/core/scene.js';
import { Color3, Color4 } from '@babylonjs/core/Maths/math.color.js';
import { AppendSceneAsync } from '@babylonjs/core/Loading/sceneLoader.js';
import '@babylonjs/core/Loading/loadingScreen.js';  // AppendSceneAsync shows (and needs) the loading screen
import '@babylonjs/loaders/glTF/index.js';
import { registerMozLightmap, unregisterMozLightmap } from './babylon_moz_lightmap.js';
export { canvasPixels } from './canvas_pixels.js';

export async function showBakedSceneBabylon({ scene, camera = 0, width, height, plugin = true }) {
  const canvas = document.createElement('canvas');
  canvas.style.width = `${width}px`;
  canvas.style.height = `${height}px`;
  document.body.appendChild(canvas);
  const engine = new Engine(canvas, false, { preserveDrawingBuffer: true, useExactSrgbConversions: true, stencil: false,
                                            premultipliedAlpha: false }, false);
  engine.setHardwareScalingLevel(1);
  engine.setSize(width, height);
  const s = new Scene(engine);
  s.clearColor = new Color4(0, 0, 0, 1);
  s.ambientColor = new Color3(0, 0, 0);
  const ip = s.imageProcessingConfiguration;  // linear → sRGB in the material shader, nothing else
  ip.toneMappingEnabled = false;
  ip.exposure = 1;
  ip.contrast = 1;
  ip.vignetteEnabled = false;
  ip.colorCurvesEnabled = false;
  ip.ditheringEnabled = false;
  if (plugin) registerMozLightmap();
  else unregisterMozLightmap();
  await AppendSceneAsync(new URL(scene, location.href).href, s);
  // The light maps hold the punctual lights' light already. (An application that keeps a light the bake left to
  // the client gets the bake's range window: Babylon's glTF loader gives KHR lights FALLOFF_GLTF and their range.)
  const lights = s.lights.length;
  for (const l of [...s.lights]) l.dispose();
  const cam = s.cameras.find(c => c._internalMetadata?.gltf?.pointers?.includes(`/cameras/${camera}`));
  if (!cam) throw new Error(`${scene}: no camera ${camera}`);
  s.activeCamera = cam;
  await s.whenReadyAsync();
  s.render();
  const lightmapped = s.materials.filter(m => m.lightmapTexture).length;
  return { width, height, lights, plugin, lightmappedMaterials: lightmapped,
           unlitMaterials: s.materials.filter(m => m.unlit).length };
}
