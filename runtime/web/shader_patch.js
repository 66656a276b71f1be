// Several plugins patch one material's shader (moz_lightmap.js's directional maps, irbake_shadowmask.js's mask,
// irbake_lightmap_scenarios.js's blend), each in its own afterRoot, in whatever order their textures arrive.
// composeShaderPatch chains them: the material's onBeforeCompile runs whatever was set before or is set later
// (a plain assignment, or another composeShaderPatch), then `patch`; customProgramCacheKey appends `key` the same
// way, so each combination compiles its own program.
export function composeShaderPatch(material, key, patch) {
  const chain = (property, outer) => {
    const previous = Object.getOwnPropertyDescriptor(material, property);
    let inner = material[property];
    Object.defineProperty(material, property, {
      get: () => outer(previous?.get ? previous.get() : inner),
      set: f => { if (previous?.set) previous.set(f); else inner = f; },
      configurable: true,
    });
  };
  chain('onBeforeCompile', inner => (shader, renderer) => { inner?.call(material, shader, renderer); patch(shader); });
  chain('customProgramCacheKey', inner => () => `${inner ? inner.call(material) : ''}+${key}`);
  material.needsUpdate = true;
}
