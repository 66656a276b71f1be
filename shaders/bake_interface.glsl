// What the GL backend (baker/evaluators/gl/gl_backend.cpp) and its light-map shaders must agree on:
// texture units and the direct-light shader's codes. #define lines only, so the same file is valid
// C++ (gl_backend.cpp includes it) and GLSL (prepended to direct_light.frag and vpl_accumulate.frag).
// Texture units: the page's G-buffer (both passes)
#define BAKE_UNIT_POSITION_WEIGHT 0
#define BAKE_UNIT_NORMAL 1
#define BAKE_UNIT_GEOMETRIC_NORMAL 4
// Texture units: the VPL pass
#define BAKE_UNIT_VPL_DEPTH 2
#define BAKE_UNIT_VPL_TABLE 3
#define BAKE_UNIT_VPL_SEE_THROUGH_DEPTH 5
// Texture units: the direct-light pass
#define BAKE_UNIT_LIGHT_CUBE 2
#define BAKE_UNIT_LIGHT_MAP 3
#define BAKE_UNIT_GLASS_CUBE 5
#define BAKE_UNIT_GLASS_MAP 6
#define BAKE_UNIT_IES_PROFILE 7
// lightType
#define BAKE_LIGHT_POINT 0
#define BAKE_LIGHT_SPOT 1
#define BAKE_LIGHT_DIRECTIONAL 2
#define BAKE_LIGHT_IES 3
// shadowKind
#define BAKE_SHADOW_CUBE 0
#define BAKE_SHADOW_PERSPECTIVE 1
#define BAKE_SHADOW_ORTHOGRAPHIC 2
