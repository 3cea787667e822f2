# Runs inside Blender (blender -b --factory-startup --python render_probes.py -- ARGS): renders
# what a probe sees with Cycles and projects it to SH3 radiance in zhc's axes.
#
#   ARGS: SCENE.gltf|.glb PROBES.json OUT.json [--res N] [--spp N] [--light x,y,z,cd]
#
# PROBES.json: {"positions": [[x, y, z], ...]} in zhc axes. OUT.json: {"sh3": [9 x [r, g, b]] per
# probe, "seconds": render time}: the radiance the camera sees, which in Cycles is the light the
# surfaces reflect and emit (punctual lights are invisible to camera rays), in zhc's units.
#
# Set-up, written down (tests/cycles/README.md):
#  * materials: each imported material becomes a Lambertian Diffuse BSDF of the glTF base colour
#    times (1 - metallic) (zhc's model of glTF materials; Principled BSDF's specular layer dropped);
#    a base colour texture the importer linked to Base Color (an sRGB Image Texture, times the
#    factor) stays linked, times (1 - metallic), into the Diffuse BSDF's colour,
#    plus an Emission of emissive x strength / 683 (zhc reads emissive x strength as cd/m^2; Cycles
#    radiance is W/(m^2 sr), 683 lm/W as the importer's lights);
#  * lights: the importer's "standard" lighting mode turns I cd into I x 4 pi / 683 W; a Cycles point
#    light of P W has intensity P / (4 pi) W/sr; radius 0. So Cycles radiance x 683 = zhc units.
#    --light adds a point light (zhc axes, candela) the same way;
#  * world black, 256 bounces of every kind, no clamping, no light threshold, box pixel filter;
#  * axes: Blender's glTF importer maps glTF (x, y, z) to Blender (x, -z, y); zhc maps glTF to
#    (z, x, y); so Blender b = (y, -x, z) of zhc and zhc = (-b_y, b_x, b_z) of Blender;
#  * six 90-degree perspective cameras per probe (a cube map); pixel (i, j) (j from the bottom, as
#    Blender stores images) looks along right*u + up*v + forward with u, v = 2 (i + 0.5) / N - 1,
#    solid angle (2 / N)^2 / (1 + u^2 + v^2)^(3/2); the projection sums L Y(w) dw.
import json
import math
import os
import sys
import tempfile
import time

import bpy
import numpy
from mathutils import Matrix, Vector

# Debian 12 pairs Blender 3.4 with NumPy 1.24, which removed the alias `numpy.bool` that Blender
# 3.4's glTF importer still uses: restore it (the builtin bool, as NumPy's deprecation says).
if not hasattr(numpy, "bool") or "bool" in getattr(numpy, "__former_attrs__", {}):
    numpy.bool = bool

argv = sys.argv[sys.argv.index("--") + 1:]
scene_path, probes_path, out_path = argv[0], argv[1], argv[2]
res, spp, extra_light = 32, 64, None
i = 3
while i < len(argv):
    if argv[i] == "--res":
        res = int(argv[i + 1]); i += 2
    elif argv[i] == "--spp":
        spp = int(argv[i + 1]); i += 2
    elif argv[i] == "--light":
        extra_light = [float(x) for x in argv[i + 1].split(",")]; i += 2
    else:
        raise SystemExit("render_probes.py: unknown argument " + argv[i])

WATTS_TO_LUMENS = 683.0

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=scene_path)
scene = bpy.context.scene

# Materials: Lambertian diffuse (+ emission), read from the imported Principled BSDF's constants.
for mat in bpy.data.materials:
    if not mat.use_nodes:
        continue
    nodes = mat.node_tree.nodes
    bsdf = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
    if bsdf is None:
        continue
    base = list(bsdf.inputs["Base Color"].default_value)[:3]
    metallic = bsdf.inputs["Metallic"].default_value
    emission = list(bsdf.inputs["Emission"].default_value)[:3]
    strength = bsdf.inputs["Emission Strength"].default_value if "Emission Strength" in bsdf.inputs else 1.0
    # A base colour texture: the importer links an Image Texture (sRGB, the sampler's interpolation
    # and UV map), times the factor where it is not 1, into Base Color; that socket is kept.
    base_link = next((l for l in mat.node_tree.links if l.to_socket == bsdf.inputs["Base Color"]), None)
    base_source = base_link.from_socket if base_link is not None else None
    for n in list(nodes):
        if base_source is None or n.type in ("BSDF_PRINCIPLED", "OUTPUT_MATERIAL"):
            nodes.remove(n)
    out = nodes.new("ShaderNodeOutputMaterial")
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = [c * (1.0 - metallic) for c in base] + [1.0]
    diffuse.inputs["Roughness"].default_value = 0.0
    if base_source is not None:
        scale = nodes.new("ShaderNodeMixRGB")  # texture x (1 - metallic)
        scale.blend_type = "MULTIPLY"
        scale.inputs["Fac"].default_value = 1.0
        scale.inputs["Color2"].default_value = [1.0 - metallic] * 3 + [1.0]
        mat.node_tree.links.new(base_source, scale.inputs["Color1"])
        mat.node_tree.links.new(scale.outputs["Color"], diffuse.inputs["Color"])
    emit = nodes.new("ShaderNodeEmission")
    emit.inputs["Color"].default_value = emission + [1.0]
    emit.inputs["Strength"].default_value = strength / WATTS_TO_LUMENS
    add = nodes.new("ShaderNodeAddShader")
    mat.node_tree.links.new(diffuse.outputs[0], add.inputs[0])
    mat.node_tree.links.new(emit.outputs[0], add.inputs[1])
    mat.node_tree.links.new(add.outputs[0], out.inputs["Surface"])

# Objects without a material: glTF's default material is fully metallic, which reflects no
# diffuse light: black here too.
black = bpy.data.materials.new("zhc_black")
black.use_nodes = True
black.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0, 0, 0, 1)
black.node_tree.nodes["Principled BSDF"].inputs["Specular"].default_value = 0.0
for obj in scene.objects:
    if obj.type == "MESH" and len(obj.data.materials) == 0:
        obj.data.materials.append(black)

def to_blender(p):
    return Vector((p[1], -p[0], p[2]))

for obj in scene.objects:
    if obj.type == "LIGHT":
        obj.data.shadow_soft_size = 0.0
if extra_light is not None:
    light = bpy.data.lights.new("zhc_point", type="POINT")
    light.energy = extra_light[3] * 4.0 * math.pi / WATTS_TO_LUMENS
    light.shadow_soft_size = 0.0
    lo = bpy.data.objects.new("zhc_point", light)
    lo.location = to_blender(extra_light[:3])
    scene.collection.objects.link(lo)

world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
scene.world = world

scene.render.engine = "CYCLES"
cy = scene.cycles
cy.device = "CPU"
cy.samples = spp
cy.use_adaptive_sampling = False
cy.use_denoising = False
cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = 256
cy.transparent_max_bounces = 8
cy.sample_clamp_direct = 0.0
cy.sample_clamp_indirect = 0.0
cy.light_sampling_threshold = 0.0
cy.caustics_reflective = cy.caustics_refractive = True
cy.pixel_filter_type = "BOX"
cy.filter_width = 1.0
cy.seed = 1
scene.render.threads_mode = "AUTO"
scene.render.resolution_x = scene.render.resolution_y = res
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.color_mode = "RGB"
scene.view_settings.view_transform = "Standard"
scene.view_settings.exposure = 0.0
scene.view_settings.gamma = 1.0

cam_data = bpy.data.cameras.new("probe")
cam_data.type = "PERSP"
cam_data.sensor_fit = "HORIZONTAL"
cam_data.angle = math.pi / 2
cam_data.clip_start = 1e-4
cam_data.clip_end = 1e5
cam = bpy.data.objects.new("probe", cam_data)
scene.collection.objects.link(cam)
scene.camera = cam

# Cube faces (Blender axes): forward and up; right = forward x up (the camera looks along -Z local
# with +Y up and +X right, so its matrix columns are right, up, -forward).
FACES = [((1, 0, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1)), ((0, 1, 0), (0, 0, 1)), ((0, -1, 0), (0, 0, 1)),
         ((0, 0, 1), (0, 1, 0)), ((0, 0, -1), (0, 1, 0))]

K0 = 0.5 / math.sqrt(math.pi)
K1 = math.sqrt(3.0 / (4.0 * math.pi))
K2 = math.sqrt(15.0 / (4.0 * math.pi))
K20 = math.sqrt(5.0 / (16.0 * math.pi))
K22 = math.sqrt(15.0 / (16.0 * math.pi))

def basis(x, y, z):
    return [K0, -K1 * y, K1 * z, -K1 * x, K2 * x * y, -K2 * y * z, K20 * (3 * z * z - 1), -K2 * x * z, K22 * (x * x - y * y)]

# Per face, the zhc direction and solid angle of each pixel (computed once).
face_tables = []
for fwd, up in FACES:
    f, u = Vector(fwd), Vector(up)
    r = f.cross(u)
    rows = []
    for j in range(res):
        v = 2.0 * (j + 0.5) / res - 1.0
        for i in range(res):
            uu = 2.0 * (i + 0.5) / res - 1.0
            d = (r * uu + u * v + f).normalized()
            dw = (2.0 / res) ** 2 / (1.0 + uu * uu + v * v) ** 1.5
            rows.append((basis(-d.y, d.x, d.z), dw))
    face_tables.append((f, u, r, rows))

probes = json.load(open(probes_path))["positions"]
tmp = tempfile.mkdtemp(prefix="zhc_cycles_")
result = []
t0 = time.time()
for pi, p in enumerate(probes):
    sh = [[0.0, 0.0, 0.0] for _ in range(9)]
    for fi, (f, u, r, rows) in enumerate(face_tables):
        m = Matrix(((r.x, u.x, -f.x, 0), (r.y, u.y, -f.y, 0), (r.z, u.z, -f.z, 0), (0, 0, 0, 1)))
        m.translation = to_blender(p)
        cam.matrix_world = m
        path = os.path.join(tmp, "p%d_f%d.exr" % (pi, fi))
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(path)
        px = list(img.pixels)
        ch = img.channels
        bpy.data.images.remove(img)
        os.remove(path)
        for k, (y, dw) in enumerate(rows):
            L = [px[k * ch + c] * WATTS_TO_LUMENS for c in range(3)]
            for c in range(9):
                w = y[c] * dw
                sh[c][0] += L[0] * w
                sh[c][1] += L[1] * w
                sh[c][2] += L[2] * w
    result.append(sh)
json.dump({"sh3": result, "seconds": time.time() - t0, "res": res, "spp": spp}, open(out_path, "w"))
