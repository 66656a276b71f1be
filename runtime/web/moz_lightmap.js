// A GLTFLoader plugin for MOZ_lightmap as irbake writes it (docs/export.md):
//   material.extensions.MOZ_lightmap = { index, texCoord: 1, intensity, extras: { colorSpace: "srgb" } }
// A map texel is irradiance/π (linear). The 8-bit PNG is sRGB-encoded when extras.colorSpace says so
// (irbake ≥ issue 13), linear otherwise; value = decode(PNG) × intensity.
// three.js treats lightMap as irradiance and shades it with BRDF_Lambert = albedo/π, so the
// lightMapIntensity it needs is intensity × π. Materials with a light map become MeshLambertMaterial
// (a physical material would add a specular term the bake does not have).
import { MeshLambertMaterial, SRGBColorSpace, NoColorSpace } from 'three';

export class MozLightmapExtension {
  constructor(parser) {
    this.parser = parser;
    this.name = 'MOZ_lightmap';
  }

  lightmapOf(materialIndex) {
    const def = this.parser.json.materials?.[materialIndex];
    return def?.extensions?.[this.name];
  }

  getMaterialType(materialIndex) {
    return this.lightmapOf(materialIndex) ? MeshLambertMaterial : null;
  }

  extendMaterialParams(materialIndex, params) {
    const moz = this.lightmapOf(materialIndex);
    if (!moz) return Promise.resolve();
    // GLTFLoader filled metallic-roughness parameters a Lambert material does not have.
    for (const key of ['metalness', 'roughness']) delete params[key];
    const srgb = moz.extras?.colorSpace === 'srgb';
    params.lightMapIntensity = (moz.intensity ?? 1) * Math.PI;
    return this.parser.assignTexture(params, 'lightMap', { index: moz.index, texCoord: moz.texCoord ?? 1 },
                                     srgb ? SRGBColorSpace : NoColorSpace);
  }
}
