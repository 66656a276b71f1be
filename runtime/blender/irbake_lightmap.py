# irbake light maps in Blender: wires MOZ_lightmap into the materials that Blender's glTF importer creates, so the
# bake shows unlit (baseColor x irradiance/pi + emissive) in the viewport and in renders: irradiance/pi is
# the EXR page, or the PNG x intensity / pi (x intensity for an older irbake's: generator irbake, no units marker).
# docs/export.md, "Blender".
#
# As an add-on (Edit > Preferences > Add-ons > Install..., enable "irbake light maps"): every File > Import >
# glTF 2.0 wires the maps. As a script, with or without the add-on installed:
#   blender --background --python runtime/blender/irbake_lightmap.py -- scene.gltf [--png] [--save out.blend]
bl_info = {
    "name": "irbake light maps",
    "description": "Shows the MOZ_lightmap light maps of an irbake glTF on the imported materials (unlit)",
    "author": "irbake",
    "version": (1, 0, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > glTF 2.0",
    "category": "Import-Export",
}

import argparse
import json
import math
import os
import struct
import sys
import types
import urllib.parse

import bpy

ADDON_NAME = "irbake_lightmap"
EXTENSION = "MOZ_lightmap"
# Scene property read by the hook during import_gltf(): False reads the PNG pages even where EXR pages exist.
PREFER_EXR_PROPERTY = "irbake_lightmap_prefer_exr"
LIGHTMAP_TEX_COORD = 1  # irbake's light maps live in TEXCOORD_1, MOZ_lightmap's default set
# The MOZ_lightmaps refused during the current import, one message each (main() exits 5 when there are any). The
# importer catches and prints whatever a hook raises, so refusals are collected here instead.
refusals = []


class LightmapRefused(ValueError):
    """A MOZ_lightmap that irview refuses (docs/refusals.md), with irview's message."""


def float32_finite(value):
    """Whether value is a number that stays finite as a 32-bit float (what irview stores): 1e39 is not."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != value:
        return False
    try:
        struct.pack("<f", value)
    except OverflowError:
        return False
    return abs(value) != float("inf")


def is_irradiance(ext):
    """Whether a MOZ_lightmap carries irbake's marker extras.irbake.mozLightmap = "irradiance"."""
    extras = ext.get("extras") if isinstance(ext, dict) else None
    marker = extras.get("irbake") if isinstance(extras, dict) else None
    return isinstance(marker, dict) and marker.get("mozLightmap") == "irradiance"


def is_older_irbake(gltf, ext):
    """Whether a MOZ_lightmap is in the older irbake convention, intensity x texel = irradiance/pi: the file's
    asset.generator starts with "irbake" and the marker is absent. Every other file follows MOZ_lightmap's own
    rule, intensity x texel = the irradiance E."""
    generator = getattr(getattr(gltf.data, "asset", None), "generator", None)
    return isinstance(generator, str) and generator.startswith("irbake") and not is_irradiance(ext)


def lightmap_of(gltf, material_index, ext):
    """(texture index, texCoord, scale) of material material_index's MOZ_lightmap ext, as irview reads it: the
    scale makes the decoded texel irradiance/pi, the value shown as baseColor x value (intensity / pi per the
    specification, the intensity for an older irbake's); texCoord and intensity default to 1. Raises
    LightmapRefused naming the material for what irview refuses."""
    name = gltf.data.materials[material_index].name if material_index is not None else None
    what = "material %s%s: MOZ_lightmap" % (material_index, " ('%s')" % name if name else "")
    if not isinstance(ext, dict):
        raise LightmapRefused("%s is not an object" % what)
    texture = ext.get("index")
    if isinstance(texture, bool) or not isinstance(texture, int):
        raise LightmapRefused("%s has no texture index" % what)
    textures = len(gltf.data.textures or [])
    if not 0 <= texture < textures:
        raise LightmapRefused("%s names texture %d, which does not exist (the file has %d)" % (what, texture, textures))
    tex_coord = ext.get("texCoord", LIGHTMAP_TEX_COORD)
    if tex_coord != LIGHTMAP_TEX_COORD or isinstance(tex_coord, bool):
        raise LightmapRefused("%s texCoord %s, but light maps use TEXCOORD_%d" % (what, json.dumps(tex_coord), LIGHTMAP_TEX_COORD))
    intensity = ext.get("intensity", 1.0)
    if not float32_finite(intensity) or intensity < 0:
        raise LightmapRefused("%s intensity %s must be a finite number ≥ 0" % (what, json.dumps(intensity)))
    return texture, tex_coord, float(intensity) / (1.0 if is_older_irbake(gltf, ext) else math.pi)


def numpy_bool_alias():
    """The 3.4 glTF importer uses np.bool, which numpy 1.24 (Debian 12) removed; it was an alias of bool."""
    try:
        import numpy
    except ImportError:
        return  # the importer itself will say that numpy is missing
    if "bool" not in numpy.__dict__:
        numpy.bool = bool


def uv_map_name(tex_coord):
    """The name Blender's 3.4 importer gives the UV layer of TEXCOORD_<tex_coord>."""
    return "UVMap" if tex_coord == 0 else "UVMap.%03d" % tex_coord


def exr_pages_by_texture(gltf):
    """Texture index -> absolute path of its float EXR page, from the root's extras.lightmapPages and each
    primitive's extras.lightmap.page; textures whose page is ambiguous or whose file is missing are left out."""
    extras = gltf.data.extras if isinstance(gltf.data.extras, dict) else {}
    pages = extras.get("lightmapPages")
    if not isinstance(pages, list):
        return {}
    folder = os.path.dirname(os.path.abspath(gltf.filename))
    page_of_texture = {}
    for mesh in gltf.data.meshes or []:
        for prim in mesh.primitives:
            record = prim.extras.get("lightmap") if isinstance(prim.extras, dict) else None
            if not isinstance(record, dict) or prim.material is None:
                continue
            material = gltf.data.materials[prim.material]
            ext = (material.extensions or {}).get(EXTENSION)
            if not isinstance(ext, dict) or "index" not in ext:
                continue
            page_of_texture.setdefault(ext["index"], set()).add(record.get("page"))
    result = {}
    for texture, page_set in page_of_texture.items():
        if len(page_set) != 1:
            continue
        page = page_set.pop()
        if isinstance(page, int) and 0 <= page < len(pages) and isinstance(pages[page], str):
            path = os.path.join(folder, urllib.parse.unquote(pages[page]))
            if os.path.isfile(path):
                result[texture] = path
    return result


def png_page(gltf, texture_index):
    """The 8-bit light-map image of a texture through the importer's own image loader (files, data URIs, GLB)."""
    from io_scene_gltf2.blender.imp.gltf2_blender_image import BlenderImage
    source = gltf.data.textures[texture_index].source
    if source is None:
        return None
    BlenderImage.create(gltf, source)
    name = gltf.data.images[source].blender_image_name
    return bpy.data.images.get(name) if name else None


def socket_value(socket):
    """The output socket that drives an input, or None when the input holds a constant."""
    return socket.links[0].from_socket if socket.is_linked else None


def feed(tree, target, source_socket, constant):
    """Links source_socket into target, or sets target's constant."""
    if source_socket is not None:
        tree.links.new(target, source_socket)
    else:
        target.default_value = constant


def wire_lightmap(material, image, tex_coord, intensity, is_float_page):
    """Replaces the material's surface with Emission(baseColor x lightmap x intensity + emissive) (intensity: the
    scale lightmap_of gives, to irradiance/pi), the
    importer's Principled BSDF kept beside it unlinked. Returns False for a material without Principled BSDF."""
    tree = material.node_tree
    pbr = next((n for n in tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
    out = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
    if pbr is None or out is None:
        return False
    x, y = pbr.location.x, pbr.location.y - 700

    uv = tree.nodes.new("ShaderNodeUVMap")
    uv.uv_map = uv_map_name(tex_coord)
    uv.location = (x - 600, y)
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.label = "irbake light map"
    tex.interpolation = "Linear"
    tex.extension = "EXTEND"  # clamp to edge, as the glTF sampler says
    tex.location = (x - 400, y)
    tree.links.new(tex.inputs["Vector"], uv.outputs["UV"])

    lit = tree.nodes.new("ShaderNodeVectorMath")
    lit.operation = "MULTIPLY"
    lit.label = "base colour x light map"
    lit.location = (x - 100, y)
    base = pbr.inputs["Base Color"]
    feed(tree, lit.inputs[0], socket_value(base), base.default_value[:3])
    tree.links.new(lit.inputs[1], tex.outputs["Color"])

    scaled = tree.nodes.new("ShaderNodeVectorMath")
    scaled.operation = "SCALE"
    scaled.label = "light-map intensity"
    scaled.location = (x + 100, y)
    tree.links.new(scaled.inputs[0], lit.outputs[0])
    # The float page holds the value itself; the PNG holds value / scale.
    scaled.inputs["Scale"].default_value = 1.0 if is_float_page else intensity

    emissive = tree.nodes.new("ShaderNodeVectorMath")
    emissive.operation = "SCALE"
    emissive.label = "emissive"
    emissive.location = (x + 100, y - 200)
    colour, strength = pbr.inputs["Emission"], pbr.inputs["Emission Strength"]
    feed(tree, emissive.inputs[0], socket_value(colour), colour.default_value[:3])
    feed(tree, emissive.inputs["Scale"], socket_value(strength), strength.default_value)

    total = tree.nodes.new("ShaderNodeVectorMath")
    total.operation = "ADD"
    total.location = (x + 300, y)
    tree.links.new(total.inputs[0], scaled.outputs[0])
    tree.links.new(total.inputs[1], emissive.outputs[0])

    shader = tree.nodes.new("ShaderNodeEmission")
    shader.label = "irbake unlit"
    shader.inputs["Strength"].default_value = 1.0
    shader.location = (x + 500, y)
    tree.links.new(shader.inputs["Color"], total.outputs[0])
    surface = shader.outputs["Emission"]

    # Blended and masked materials keep their alpha: a transparent mix by the importer's alpha.
    alpha = pbr.inputs["Alpha"]
    if material.blend_method != "OPAQUE" and (alpha.is_linked or alpha.default_value < 1.0):
        clear = tree.nodes.new("ShaderNodeBsdfTransparent")
        clear.location = (x + 500, y - 150)
        mix = tree.nodes.new("ShaderNodeMixShader")
        mix.location = (x + 700, y)
        feed(tree, mix.inputs["Fac"], socket_value(alpha), alpha.default_value)
        tree.links.new(mix.inputs[1], clear.outputs[0])
        tree.links.new(mix.inputs[2], surface)
        surface = mix.outputs[0]

    for link in list(out.inputs["Surface"].links):
        tree.links.remove(link)
    tree.links.new(out.inputs["Surface"], surface)
    material["irbake_lightmap"] = image.filepath or image.name
    return True


class glTF2ImportUserExtension:
    """The importer calls this after creating each material (Blender 3.4's user-extension hooks: it looks for a
    class of this name in every enabled add-on)."""

    def __init__(self):  # one per import
        self.exr_pages = None
        del refusals[:]

    def gather_import_material_after_hook(self, pymaterial, vertex_color, blender_material, gltf):
        extensions = pymaterial.extensions or {}
        if EXTENSION not in extensions:
            return
        index = next((i for i, m in enumerate(gltf.data.materials or []) if m is pymaterial), None)
        try:
            texture, tex_coord, intensity = lightmap_of(gltf, index, extensions[EXTENSION])
        except LightmapRefused as e:
            # Left as imported: a wrong map is never shown. The command line exits 5 (main()).
            refusals.append(str(e))
            print("irbake_lightmap: %s: %s" % (gltf.filename, e), file=sys.stderr)
            return
        ext = extensions[EXTENSION]
        if self.exr_pages is None:
            prefer_exr = bpy.context.scene.get(PREFER_EXR_PROPERTY, True)
            self.exr_pages = exr_pages_by_texture(gltf) if prefer_exr else {}
        exr = self.exr_pages.get(texture)
        if exr is not None:
            image = bpy.data.images.load(exr, check_existing=True)
            image.colorspace_settings.name = "Non-Color"  # linear irradiance/pi, no transfer curve
        else:
            image = png_page(gltf, texture)
            if image is None:
                print("irbake_lightmap: material %r: light-map texture %d has no image" % (blender_material.name, texture))
                return
            srgb = isinstance(ext.get("extras"), dict) and ext["extras"].get("colorSpace") == "srgb"
            image.colorspace_settings.name = "sRGB" if srgb else "Non-Color"
        if not wire_lightmap(blender_material, image, tex_coord, intensity, exr is not None):
            print("irbake_lightmap: material %r has no Principled BSDF (unlit or specular-glossiness): left as imported"
                  % blender_material.name)


def import_gltf(filepath, prefer_exr=True, **importer_options):
    """Imports a glTF with Blender's importer and this module's hook (registered for the call when the add-on
    is not enabled). prefer_exr=False reads the 8-bit PNG pages even where float EXR pages exist."""
    numpy_bool_alias()
    addons = bpy.context.preferences.addons
    temporary = None
    if ADDON_NAME not in addons.keys():
        # The importer looks the hook up as sys.modules[add-on name].glTF2ImportUserExtension.
        if ADDON_NAME not in sys.modules:
            shim = types.ModuleType(ADDON_NAME)
            shim.glTF2ImportUserExtension = glTF2ImportUserExtension
            sys.modules[ADDON_NAME] = shim
        temporary = addons.new()
        temporary.module = ADDON_NAME
    scene = bpy.context.scene
    scene[PREFER_EXR_PROPERTY] = bool(prefer_exr)
    try:
        return bpy.ops.import_scene.gltf(filepath=filepath, **importer_options)
    finally:
        del scene[PREFER_EXR_PROPERTY]
        if temporary is not None:
            addons.remove(temporary)


def register():
    numpy_bool_alias()


def unregister():
    pass


def main(argv):
    parser = argparse.ArgumentParser(prog="irbake_lightmap.py",
                                     description="Import an irbake glTF into Blender with its light maps wired in.")
    parser.add_argument("scene", help="the baked .gltf or .glb")
    parser.add_argument("--png", action="store_true", help="read the 8-bit PNG pages even where EXR pages exist")
    parser.add_argument("--empty", action="store_true", help="remove every object of the open file first")
    parser.add_argument("--save", metavar="FILE.blend", help="save the result (images packed into it)")
    args = parser.parse_args(argv)
    if not os.path.isfile(args.scene):
        print("irbake_lightmap: %s: no such file" % args.scene, file=sys.stderr)
        return 3
    if args.empty:
        for obj in list(bpy.data.objects):
            bpy.data.objects.remove(obj)
    if import_gltf(os.path.abspath(args.scene), prefer_exr=not args.png) != {"FINISHED"}:
        print("irbake_lightmap: %s: the glTF importer failed" % args.scene, file=sys.stderr)
        return 4
    if refusals:  # irview's class for them: InvalidData (5); each was printed when it was met
        print("irbake_lightmap: %s: %d light map(s) refused, left as imported" % (args.scene, len(refusals)), file=sys.stderr)
        return 5
    wired = [m.name for m in bpy.data.materials if "irbake_lightmap" in m]
    print("irbake_lightmap: %d material(s) with light maps: %s" % (len(wired), ", ".join(sorted(wired))))
    if args.save:
        bpy.ops.file.pack_all()
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save))
    return 0


if __name__ == "__main__":
    arguments = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    status = main(arguments)
    if status != 0 or bpy.app.background:
        sys.exit(status)
