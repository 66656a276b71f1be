// What irview refuses in a MOZ_lightmap (docs/refusals.md), with irview's messages, for the three.js and Babylon.js
// plugins: a map is shown as irview shows it or not at all, never negative, NaN, on the wrong UVs or from a
// texture the file does not have. A missing texCoord is 1 and a missing intensity 1 (MOZ_lightmap's defaults).
// Units (docs/export.md): MOZ_lightmap's own rule, E = intensity × sRGBToLinear(texel) the irradiance, holds for
// every file but an older irbake's: asset.generator starting with "irbake" and no marker
// extras.irbake.mozLightmap = "irradiance" (which current irbake exports carry); its intensity × texel is
// irradiance/π.
export const LIGHTMAP_TEXCOORD = 1;  // irbake's light maps live in TEXCOORD_1; irview reads no other set

// Whether a MOZ_lightmap extension carries irbake's irradiance marker.
export function mozLightmapIsIrradiance(ext) {
  return ext?.extras?.irbake?.mozLightmap === 'irradiance';
}

// Whether MOZ_lightmap `ext` of glTF document `json` is in the older irbake convention (intensity × texel =
// irradiance/π): an irbake generator and no marker.
export function mozLightmapIsOlderIrbake(json, ext) {
  const generator = json?.asset?.generator;
  return typeof generator === 'string' && generator.startsWith('irbake') && !mozLightmapIsIrradiance(ext);
}

// Material `materialIndex`'s MOZ_lightmap `ext` of glTF document `json`: { index, texCoord, intensity, irradiance }
// when irview would show it (irradiance: the factor that makes the decoded texel the irradiance E, the intensity
// per the specification, intensity × π for an older irbake's); else throws an Error naming the material and the field.
export function checkMozLightmap(json, materialIndex, ext) {
  const name = json.materials?.[materialIndex]?.name;
  const what = `material ${materialIndex}${name ? ` ('${name}')` : ''}: MOZ_lightmap`;
  if (typeof ext !== 'object' || ext === null || Array.isArray(ext)) throw new Error(`${what} is not an object`);
  if (!Number.isInteger(ext.index)) throw new Error(`${what} has no texture index`);
  const textures = Array.isArray(json.textures) ? json.textures.length : 0;
  if (ext.index < 0 || ext.index >= textures)
    throw new Error(`${what} names texture ${ext.index}, which does not exist (the file has ${textures})`);
  const texCoord = 'texCoord' in ext ? ext.texCoord : LIGHTMAP_TEXCOORD;
  if (texCoord !== LIGHTMAP_TEXCOORD)
    throw new Error(`${what} texCoord ${JSON.stringify(texCoord)}, but light maps use TEXCOORD_${LIGHTMAP_TEXCOORD}`);
  const intensity = 'intensity' in ext ? ext.intensity : 1;
  // Finite as a 32-bit float, as irview stores it: 1e39 would be Infinity in the shader.
  if (typeof intensity !== 'number' || !(intensity >= 0) || !Number.isFinite(Math.fround(intensity)))
    throw new Error(`${what} intensity ${JSON.stringify(intensity)} must be a finite number ≥ 0`);
  const irradiance = mozLightmapIsOlderIrbake(json, ext) ? intensity * Math.PI : intensity;
  return { index: ext.index, texCoord, intensity, irradiance };
}
