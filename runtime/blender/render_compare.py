# Renders a baked glTF from its first camera with Cycles after importing it through irbake_lightmap.py, and
# compares each render with a reference PNG (irview's screenshot of the same camera): mean absolute difference
# in 8-bit codes over the RGB channels. Three imports: the float EXR pages, the 8-bit PNG pages, and Blender's
# importer alone (the control, which shows no light map and must differ). Writes the renders and results.json.
#   blender --background --factory-startup --python render_compare.py -- --scene S.gltf --reference R.png
#           --out DIR [--width W --height H --samples N --max-mean-abs-exr M --max-mean-abs-png M
#           --min-control-mean-abs C]
import argparse
import json
import os
import sys
import time

import bpy

sys.dont_write_bytecode = True  # no __pycache__ in the source folder: tests write only under build/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import irbake_lightmap  # noqa: E402  (the add-on beside this file)


def set_up_render(width, height, samples):
    """Cycles on the CPU from the glTF camera, no colour transform but the sRGB curve."""
    scene = bpy.context.scene
    cameras = [o for o in scene.objects if o.type == "CAMERA"]
    if not cameras:
        raise SystemExit("render_compare: the scene has no camera")
    scene.camera = sorted(cameras, key=lambda o: o.name)[0]
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 0  # emission seen by camera rays is the whole picture
    # irview rasterises one sample at each pixel centre; one Cycles sample with a 0.01-pixel box filter lands
    # there too (emission-only shading has no other noise). More samples spread over the pixel: edges differ.
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 0.01
    scene.cycles.seed = 0
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.dither_intensity = 0.0
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = "Standard"  # the sRGB curve alone, no Filmic tone map
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    if scene.world is not None:
        scene.world = None  # black background, as irview's clear colour for a scene without sky


def rgb_codes(path):
    """An 8-bit PNG's RGB as a list of floats in codes 0..255, rows as Blender loads them."""
    import numpy
    image = bpy.data.images.load(path, check_existing=False)
    pixels = numpy.empty(image.size[0] * image.size[1] * 4, dtype=numpy.float32)
    image.pixels.foreach_get(pixels)
    size = tuple(image.size)
    bpy.data.images.remove(image)
    return size, pixels.reshape(-1, 4)[:, :3] * 255.0


def compare(render_path, reference_path):
    import numpy
    size, ours = rgb_codes(render_path)
    ref_size, ref = rgb_codes(reference_path)
    if size != ref_size:
        raise SystemExit("render_compare: %s is %dx%d, the reference %s %dx%d"
                         % (render_path, size[0], size[1], reference_path, ref_size[0], ref_size[1]))
    diff = numpy.abs(numpy.rint(ours) - numpy.rint(ref))
    return {
        "meanAbs": float(diff.mean()),
        "maxAbs": float(diff.max()),
        "fractionOver8": float((diff > 8).mean()),
        "meanRgb": [float(v) for v in ours.mean(axis=0)],
        "referenceMeanRgb": [float(v) for v in ref.mean(axis=0)],
    }


def render_variant(name, scene_path, args):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    start = time.monotonic()
    if name == "control":
        irbake_lightmap.numpy_bool_alias()
        status = bpy.ops.import_scene.gltf(filepath=scene_path)
    else:
        status = irbake_lightmap.import_gltf(scene_path, prefer_exr=(name == "exr"))
    if status != {"FINISHED"}:
        raise SystemExit("render_compare: importing %s failed" % scene_path)
    wired = sorted(m.name for m in bpy.data.materials if "irbake_lightmap" in m)
    pages = sorted({os.path.basename(m["irbake_lightmap"]) for m in bpy.data.materials if "irbake_lightmap" in m})
    set_up_render(args.width, args.height, args.samples)
    out = os.path.join(args.out, "blender_%s.png" % name)
    bpy.context.scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
    result = compare(out, args.reference)
    result.update({"wiredMaterials": wired, "pages": pages, "seconds": time.monotonic() - start})
    return result


def main(argv):
    parser = argparse.ArgumentParser(prog="render_compare.py")
    parser.add_argument("--scene", required=True)
    parser.add_argument("--reference", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=160)
    parser.add_argument("--samples", type=int, default=1)
    parser.add_argument("--max-mean-abs-exr", type=float, default=0.5, help="limit with the float EXR pages")
    parser.add_argument("--max-mean-abs-png", type=float, default=1.0, help="limit with the 8-bit PNG pages")
    parser.add_argument("--min-control-mean-abs", type=float, default=20.0,
                        help="the importer alone must differ by at least this much")
    args = parser.parse_args(argv)
    scene_path = os.path.abspath(args.scene)
    os.makedirs(args.out, exist_ok=True)
    results = {name: render_variant(name, scene_path, args) for name in ("exr", "png", "control")}
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump(results, f, indent=2)
    failures = []
    for name, r in results.items():
        print("render_compare: %-7s mean |diff| %.3f  max %.0f  >8: %.4f%%  mean RGB %s (irview %s)  %d material(s) "
              "from %s  %.1f s" % (name, r["meanAbs"], r["maxAbs"], 100 * r["fractionOver8"],
                                   ", ".join("%.1f" % v for v in r["meanRgb"]),
                                   ", ".join("%.1f" % v for v in r["referenceMeanRgb"]),
                                   len(r["wiredMaterials"]), ", ".join(r["pages"]) or "-", r["seconds"]))
    for name in ("exr", "png"):
        if not results[name]["wiredMaterials"]:
            failures.append("%s: no material got a light map" % name)
        limit = args.max_mean_abs_exr if name == "exr" else args.max_mean_abs_png
        if results[name]["meanAbs"] > limit:
            failures.append("%s: mean |diff| %.3f > %.3f" % (name, results[name]["meanAbs"], limit))
    if not any(p.endswith(".exr") for p in results["exr"]["pages"]):
        failures.append("exr: the float EXR pages were not used")
    if any(p.endswith(".exr") for p in results["png"]["pages"]):
        failures.append("png: an EXR page was used")
    if results["control"]["meanAbs"] < args.min_control_mean_abs:
        failures.append("control: the importer alone is within %.3f of irview (< %.3f): the comparison cannot see "
                        "the light map" % (results["control"]["meanAbs"], args.min_control_mean_abs))
    for f in failures:
        print("render_compare: FAIL " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []))
