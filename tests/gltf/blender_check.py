# Runs inside Blender (tests/cli/test_export_blender.sh):
#   blender -b --factory-startup --python blender_check.py -- FILE.glb SCENE.json NFRAMES
# Imports the glTF with Blender's own importer (io_scene_gltf2) and checks, after mapping Blender's
# +z-up axes back to ours (Blender (X, Y, Z) = glTF (x, -z, y)), that the camera's position and
# viewing direction and the sun's direction equal what the scene's angles give (scene.h
# conventions, recomputed here from SCENE.json) within 1e-4, the vertical field of view within
# 1e-6, the sun's strength equals max(irradiance) in W/m^2 (the importer divides lux by
# 683 lm/W), the water has NFRAMES shape keys besides the basis, and the extras arrived as the
# scene's custom property "godrays". Prints the errors; exits 1 on a failed check.
import json
import math
import sys

import numpy as np

# Debian bookworm's Blender 3.4 importer uses np.bool, which bookworm's NumPy 1.24 removed
# (a packaging mismatch, not ours): restore the alias before importing.
if "bool" in getattr(np, "__former_attrs__", {}):
    np.bool = bool

import addon_utils  # noqa: E402
import bpy  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
path, scene_path, nframes = argv[0], argv[1], int(argv[2])
TOL = 1e-4
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)


addon_utils.enable("io_scene_gltf2", default_set=True)
bpy.ops.wm.read_factory_settings(use_empty=True)
addon_utils.enable("io_scene_gltf2", default_set=True)
bpy.ops.import_scene.gltf(filepath=path)

sc = json.load(open(scene_path))
rad = math.pi / 180.0


def to_ours(v):  # Blender (X, Y, Z) -> glTF / scene (x, y, z) = (X, Z, -Y)
    return (v[0], v[2], -v[1])


def dist(a, b):
    return max(abs(p - q) for p, q in zip(a, b))


cam = bpy.data.objects["camera"]
yaw, pitch = sc["camera"]["yaw_deg"] * rad, sc["camera"]["pitch_deg"] * rad
fwd_want = (math.cos(pitch) * math.sin(yaw), math.sin(pitch), math.cos(pitch) * math.cos(yaw))
m = cam.matrix_world
fwd = to_ours(tuple(-c for c in m.to_3x3().col[2]))  # a Blender camera looks along local -Z
pos = to_ours(tuple(m.translation))
right = to_ours(tuple(m.to_3x3().col[0]))
e_pos, e_fwd = dist(pos, sc["camera"]["position_m"]), dist(fwd, fwd_want)
e_fov = abs(cam.data.angle_y - sc["camera"]["fov_deg"] * rad)
check(e_pos <= TOL, f"camera position off by {e_pos}")
check(e_fwd <= TOL, f"camera direction off by {e_fwd}")
check(abs(right[1]) <= TOL, f"camera not upright: right.y = {right[1]}")
check(cam.data.sensor_fit == "VERTICAL" and e_fov <= 1e-6, f"camera vertical fov off by {e_fov}")

sun = bpy.data.objects["sun"]
el, az = sc["sun"]["elevation_deg"] * rad, sc["sun"]["azimuth_deg"] * rad
dir_want = (-math.cos(el) * math.sin(az), -math.sin(el), -math.cos(el) * math.cos(az))
sdir = to_ours(tuple(-c for c in sun.matrix_world.to_3x3().col[2]))  # lights shine along local -Z
e_sun = dist(sdir, dir_want)
E = sc["sun"].get("irradiance", [1, 1, 1])
e_energy = abs(sun.data.energy - max(E)) / max(E)
check(sun.data.type == "SUN", f"sun imported as {sun.data.type}")
check(e_sun <= TOL, f"sun direction off by {e_sun}")
check(e_energy <= TOL, f"sun strength {sun.data.energy} W/m^2, scene max irradiance {max(E)}")

water = bpy.data.objects["water"].data
nkeys = len(water.shape_keys.key_blocks) - 1 if water.shape_keys else 0
check(nkeys == nframes, f"water has {nkeys} shape keys, want {nframes}")
g = bpy.context.scene.get("godrays")
check(g is not None and abs(g["medium"]["ior"] - sc["medium"].get("ior", 1.333)) < 1e-12,
      "extras not imported as the scene's custom property 'godrays'")

print(f"blender_check: Blender {bpy.app.version_string}: camera position {e_pos:.2e}, direction {e_fwd:.2e}, "
      f"fov {e_fov:.2e}; sun direction {e_sun:.2e}, strength {e_energy:.2e}; {nkeys} shape keys")
for f in failures:
    print("FAIL: " + f)
sys.stdout.flush()
sys.exit(1 if failures else 0)
