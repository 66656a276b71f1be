"""Gives a baked Sponza glTF the "overview" camera of scenes.py (SPONZA_CAMERAS[0]) as its camera 0, with the
aspect ratio of a W × H render, so that irview --camera 0 and the clients draw the same view.
Usage: python3 bench/cycles/add_sponza_camera.py SCENE.gltf W H   (rewrites SCENE.gltf in place)"""
import json
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source folder
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from scenes import SPONZA_CAMERAS, look_at_quat  # noqa: E402


def add_overview_camera(path, width, height):
    doc = json.load(open(path))
    name, eye, target, yfov = SPONZA_CAMERAS[0]
    doc["cameras"] = [{"type": "perspective", "name": name,
                       "perspective": {"yfov": math.radians(yfov), "aspectRatio": width / height, "znear": 0.05}}]
    doc["nodes"].append({"name": name, "camera": 0, "translation": list(eye), "rotation": list(look_at_quat(eye, target))})
    doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)
    json.dump(doc, open(path, "w"))


if __name__ == "__main__":
    if len(sys.argv) != 4:
        raise SystemExit(__doc__)
    add_overview_camera(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]))
