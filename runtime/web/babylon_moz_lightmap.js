// A Babylon.js glTF loader extension for MOZ_lightmap as irbake writes it (docs/export.md):
//   material.extensions.MOZ_lightmap = { index, texCoord: 1, intensity,
//                                         extras: { colorSpace: "srgb", irbake: { mozLightmap: "irradiance" } } }
// decode(PNG) × intensity is the irradiance E (MOZ_lightmap's own rule), irradiance/π for an older irbake's
// (generator irbake, no irradiance marker; moz_lightmap_rules.js); decode the sRGB curve when
// extras.colorSpace says so. irview shows baseColour × E/π + emissive.
//
// Babylon's PBR shader (pbrBlockFinalColorComposition) adds a light map to the lit colour unless
// useLightmapAsShadowmap is set, in which case it multiplies the colour by the map before adding the emission.
// An unlit PBR material's colour is its base colour, so unlit + useLightmapAsShadowmap gives exactly
// baseColour × map + emissive, with no scene light (the map holds all the light). The map reads TEXCOORD_1
// (coordinatesIndex 1) and its level is the factor that makes the decoded texel E/π. Render with an engine made with
// useExactSrgbConversions: true, so the sRGB decode and encode are the exact curves irview uses.
//
// A MOZ_lightmap irview refuses (moz_lightmap_rules.js) fails the load with an Error naming the material.
// Use: registerMozLightmap() once before loading (import '@babylonjs/loaders/glTF/index.js' too).
import { GLTFLoader } from '@babylonjs/loaders/glTF/2.0/glTFLoader.js';
import { registerGLTFExtension, unregisterGLTFExtension } from '@babylonjs/loaders/glTF/2.0/glTFLoaderExtensionRegistry.js';
import { checkMozLightmap } from './moz_lightmap_rules.js';

const NAME = 'MOZ_lightmap';

export class MozLightmapBabylon {
  constructor(loader) {
    this.name = NAME;
    this.order = 100;  // before KHR_materials_emissive_strength (170), which it lets load through the loader
    this._loader = loader;
    this.enabled = loader.isExtensionUsed(NAME);
  }

  dispose() { this._loader = null; }

  loadMaterialPropertiesAsync(context, material, babylonMaterial) {
    return GLTFLoader.LoadExtensionAsync(context, material, NAME, async (extensionContext, extension) => {
      // Everything else of the material (base colour, emission, other extensions) as the loader reads it.
      await this._loader.loadMaterialPropertiesAsync(context, material, babylonMaterial);
      if (!('lightmapTexture' in babylonMaterial) || !('unlit' in babylonMaterial))
        throw new Error(`${extensionContext}: needs a PBR material (got ${babylonMaterial.getClassName()})`);
      // Refused as irview refuses it (a negative or NaN intensity, a texture the file lacks, another UV set).
      const { index, texCoord, irradiance } = checkMozLightmap(this._loader.gltf, material.index, extension);
      await this._loader.loadTextureInfoAsync(extensionContext, { index, texCoord },
        texture => {
          texture.name = `${babylonMaterial.name} (MOZ_lightmap)`;
          texture.gammaSpace = extension.extras?.colorSpace === 'srgb';
          texture.level = irradiance / Math.PI;
          babylonMaterial.lightmapTexture = texture;
        });
      babylonMaterial.useLightmapAsShadowmap = true;
      babylonMaterial.unlit = true;
    });
  }
}

// Registers the extension with Babylon's glTF 2.0 loader (again: replaces an earlier registration).
export function registerMozLightmap() {
  unregisterGLTFExtension(NAME);
  registerGLTFExtension(NAME, true, loader => new MozLightmapBabylon(loader));
}

export function unregisterMozLightmap() { unregisterGLTFExtension(NAME); }
