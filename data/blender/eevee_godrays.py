# Blender (3.4) script of the `eevee` technique (src/realtime/eevee.c, docs/engines.md section 5):
# builds the god-ray scene in Eevee from the project's glTF export and a request written by
# godrays, renders the medium-on and medium-off frames as linear float EXRs, and reports the
# render time. godrays runs it as
#
#   xvfb-run -a blender -b --factory-startup --python eevee_godrays.py -- REQUEST.json
#   xvfb-run -a blender -b --factory-startup --python eevee_godrays.py -- --serve
#
# (--serve: one request path per line on stdin, for as many renders as godrays asks; the
# scene is rebuilt for each request).
#
# The request (all lengths in metres, directions in godrays' axes: +y up, converted here):
#   gltf        the scene as `godrays export` writes it (water, seabed, occluders, camera)
#   out_on      EXR path of the frame with the medium
#   out_off     EXR path of the frame without it ("" : not rendered)
#   width, height
#   sun         dir (the REFRACTED direction light travels under water), irradiance (W/m^2
#               per RGB channel on a plane perpendicular to dir, just below the surface),
#               angle_rad (the sun's angular diameter seen from under the water)
#   medium      scattering, absorption (1/m per channel, density scale applied), g
#   box         min, max: the medium's axis-aligned box
#   eevee       Eevee's volumetric settings (names below)
#
# Everything physical is computed by godrays (refraction, Fresnel, coefficients); this script
# only maps it onto Blender's objects. Why each choice: docs/engines.md section 5.
import json
import sys
import time
import traceback

import bpy
import numpy as np
from mathutils import Vector

# Debian bookworm's Blender 3.4.1 glTF importer calls np.bool, removed by NumPy 1.24.
if not hasattr(np, "bool"):
    np.bool = bool

DONE = "GODRAYS_EEVEE_DONE"
FAIL = "GODRAYS_EEVEE_ERROR"


def log(msg):
    print("eevee_godrays: " + msg, flush=True)


def to_blender(v):
    """glTF / godrays (x, y, z), +y up -> Blender (x, -z, y), +z up (the importer's mapping)."""
    return Vector((v[0], -v[2], v[1]))


def black_material(name, casts_shadow):
    """Opaque black (emission 0): the surfaces block the view (the depth buffer ends the
    camera rays there, as the ground truth's rays end) but add no light of their own."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    em.inputs["Strength"].default_value = 0.0
    nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
    mat.blend_method = "OPAQUE"
    mat.shadow_method = "OPAQUE" if casts_shadow else "NONE"
    return mat


def volume_material(name, node_type, color, density, anisotropy):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    vol = nt.nodes.new(node_type)
    vol.inputs["Color"].default_value = (color[0], color[1], color[2], 1.0)
    vol.inputs["Density"].default_value = density
    if anisotropy is not None:
        vol.inputs["Anisotropy"].default_value = anisotropy
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    return mat


def box_object(name, lo, hi, mat):
    """An axis-aligned box (godrays axes) holding a volume material. Eevee (legacy) fills an
    object's bounding box with its volume, so a box is exactly what it renders."""
    a, b = to_blender(lo), to_blender(hi)
    mn = Vector((min(a.x, b.x), min(a.y, b.y), min(a.z, b.z)))
    mx = Vector((max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)))
    verts = [(x, y, z) for x in (mn.x, mx.x) for y in (mn.y, mx.y) for z in (mn.z, mx.z)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def build(req):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=req["gltf"])
    scene = bpy.context.scene
    # the imported in-air sun is replaced by the underwater one below
    for ob in [o for o in scene.objects if o.type == "LIGHT"]:
        bpy.data.objects.remove(ob, do_unlink=True)
    cams = [o for o in scene.objects if o.type == "CAMERA"]
    if not cams:
        raise RuntimeError("the glTF file has no camera")
    scene.camera = cams[0]
    # Eevee marches the sun's path through the froxel volume only up to the camera frustum's
    # boundary (light_volume_shadow), in volumetric_shadow_samples steps: with the exported far
    # plane (2000 m) the steps miss the medium entirely. The far plane at the volumetric end
    # keeps the frustum (and the march) where the froxels are.
    cams[0].data.clip_end = req["eevee"]["end"]

    # surfaces: black; the water and the seabed cast no shadow (sunlight enters through the
    # water, refracted: its direction and irradiance are the sun's below), occluders do
    shadowing = black_material("godrays_occluder", True)
    clear = black_material("godrays_surface", False)
    for ob in scene.objects:
        if ob.type != "MESH":
            continue
        ob.data.materials.clear()
        ob.data.materials.append(clear if ob.name.split(".")[0] in ("water", "seabed") else shadowing)
        for poly in ob.data.polygons:
            poly.material_index = 0

    # the medium: two coincident boxes, one scattering, one absorbing. Eevee sums their
    # extinction (scatter + absorption) and averages the phase only over objects that scatter,
    # whereas an Add Shader in one material would halve g (closure_add averages anisotropy).
    med = req["medium"]
    sig_s, sig_a = med["scattering"], med["absorption"]
    box_object("godrays_scatter", req["box"]["min"], req["box"]["max"],
               volume_material("godrays_scatter", "ShaderNodeVolumeScatter", sig_s, 1.0, med["g"]))
    amax = max(sig_a)
    if amax > 0:
        # Volume Absorption: absorption = (1 - color) * density
        col = [1.0 - a / amax for a in sig_a]
        box_object("godrays_absorb", req["box"]["min"], req["box"]["max"],
                   volume_material("godrays_absorb", "ShaderNodeVolumeAbsorption", col, amax, None))

    # the sun under the water: the refracted direction and the irradiance just below the surface
    sun = req["sun"]
    e = sun["irradiance"]
    emax = max(e)
    light = bpy.data.lights.new("godrays_sun", "SUN")
    light.energy = emax  # W/m^2: Eevee's volume light of a sun is color * energy * volume_factor
    light.color = [c / emax for c in e] if emax > 0 else (1.0, 1.0, 1.0)
    light.angle = sun["angle_rad"]
    light.use_shadow = True
    light.use_contact_shadow = False
    light.volume_factor = 1.0
    ev = req["eevee"]
    light.shadow_cascade_count = 4
    light.shadow_cascade_max_distance = ev["end"]
    light.shadow_cascade_fade = 0.1
    sun_ob = bpy.data.objects.new("godrays_sun", light)
    scene.collection.objects.link(sun_ob)
    sun_ob.rotation_mode = "QUATERNION"
    sun_ob.rotation_quaternion = to_blender(sun["dir"]).normalized().to_track_quat("-Z", "Y")

    # a black world: no ambient light in the froxels (irradiance_volumetric) or the background
    world = bpy.data.worlds.new("godrays_black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    r = scene.render
    r.engine = "BLENDER_EEVEE"
    r.resolution_x, r.resolution_y, r.resolution_percentage = req["width"], req["height"], 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.filter_size = 0.0          # no reconstruction blur: one pixel = its own samples
    r.film_transparent = False
    r.use_motion_blur = False
    r.use_compositing = False
    r.use_sequencer = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGB"
    r.image_settings.exr_codec = "ZIP"
    r.use_file_extension = False
    # linear and unexposed: the EXR holds scene-referred values; Standard, exposure 0, gamma 1
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0

    ee = scene.eevee
    ee.taa_render_samples = ev["taa_samples"]
    ee.use_volumetric_lights = True
    ee.use_volumetric_shadows = ev["volumetric_shadows"]
    ee.volumetric_shadow_samples = ev["shadow_samples"]
    ee.volumetric_tile_size = str(ev["tile_size"])
    ee.volumetric_samples = ev["samples"]
    ee.volumetric_sample_distribution = ev["distribution"]
    ee.volumetric_start = ev["start"]
    ee.volumetric_end = ev["end"]
    ee.volumetric_light_clamp = ev["light_clamp"]
    ee.use_soft_shadows = ev["soft_shadows"]
    ee.shadow_cascade_size = str(ev["cascade_size"])
    ee.use_shadow_high_bitdepth = True
    for flag in ("use_bloom", "use_ssr", "use_gtao", "use_motion_blur"):
        setattr(ee, flag, False)
    return scene


def render(scene, path):
    scene.render.filepath = path
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return 1000.0 * (time.perf_counter() - t0)


def handle(path):
    with open(path, "r", encoding="utf-8") as f:
        req = json.load(f)
    scene = build(req)
    ms = render(scene, req["out_on"])
    if req.get("out_off"):
        for ob in scene.objects:
            if ob.name.startswith(("godrays_scatter", "godrays_absorb")):
                ob.hide_render = True
        ms += render(scene, req["out_off"])
    print("%s %.3f" % (DONE, ms), flush=True)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if argv == ["--serve"]:
        for line in sys.stdin:
            line = line.strip()
            if not line:
                continue
            try:
                handle(line)
            except Exception as exc:  # report and keep serving
                traceback.print_exc()
                print("%s %s" % (FAIL, str(exc).replace("\n", " ")), flush=True)
        return 0
    if len(argv) != 1:
        print("%s usage: ... --python eevee_godrays.py -- REQUEST.json | --serve" % FAIL, flush=True)
        return 2
    try:
        handle(argv[0])
    except Exception as exc:
        traceback.print_exc()
        print("%s %s" % (FAIL, str(exc).replace("\n", " ")), flush=True)
        return 1
    return 0


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    if code:
        # Blender -b --python exits 0 after a script that raised; make a failure visible
        import os
        os._exit(code)
