# Builds, in Blender Cycles, the scene of an atmos path-tracer scene file with a grey
# analytic medium over a VDB density grid (docs/interop.md, read backwards), renders it on
# the CPU and writes a float OpenEXR. Run by bench/cycles/run.sh:
#
#   blender -b --factory-startup -noaudio -P cycles_scene.py -- --scene S.json --vdb F.vdb \
#       --offset X,Y,Z --rgb-scale R,G,B --samples N --threads T --out OUT.exr \
#       [--density-scale D] [--seed N] [--step-rate R] [--width W --height H]
#       [--voxel-shift S --voxel-size V] [--mode scene|transmittance]
#
# --offset is where atmos puts the grid's origin (its world = the VDB's world + offset, in
# atmos's frame: x east, y up, z south); run.sh takes it from `atmos volume info`.
# --rgb-scale is the colour of the sun lamp: atmos's EXR values for a grey spectrum of radiance
# 1 (W m^-2 sr^-1 nm^-1) in its rgb mode, so that the Cycles image comes out in atmos's units.
# Prints one line "cycles-timing: samples N sync_s A render_s B total_s C" at the end.
import json
import math
import sys
import time

import bpy
import _cycles
from mathutils import Matrix, Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    a = {"density-scale": "1", "seed": "1", "step-rate": "1", "width": "", "height": "", "mode": "scene",
         "voxel-shift": "0"}
    i = 0
    while i < len(argv):
        if not argv[i].startswith("--") or i + 1 >= len(argv):
            sys.exit("cycles_scene.py: bad argument %r" % argv[i])
        a[argv[i][2:]] = argv[i + 1]
        i += 2
    for k in ("scene", "vdb", "offset", "rgb-scale", "samples", "threads", "out"):
        if k not in a:
            sys.exit("cycles_scene.py: --%s is required" % k)
    return a


def vec(s):
    return [float(x) for x in s.split(",")]


def to_blender(p):
    """atmos (x east, y up, z south) to Blender (x east, y north, z up)."""
    return Vector((p[0], -p[2], p[1]))


def main():
    a = parse_args()
    sc = json.load(open(a["scene"]))
    cam_d, sun_d = sc["camera"], sc["sun"]
    part = sc["particles"]["cloud"]
    lobes = part["lobes"]
    if len(lobes) != 1 or lobes[0]["type"] != "hg":
        sys.exit("cycles_scene.py: the particle must have one HG lobe")
    g = lobes[0]["g"]
    sigma_t = part["sigma_ext_m2"] * float(a["density-scale"]) * sc["volume"].get("density_scale", 1.0)
    albedo = part["albedo"]
    # --mode transmittance: a pure absorber in front of a uniform background of radiance 1 and
    # no sun, so that each pixel is the transmittance exp(-tau) of the volume along it (a check
    # of the geometry and the optical depth against atmos)
    transmittance = a["mode"] == "transmittance"
    if transmittance:
        albedo = 0.0
    width = int(a["width"] or sc["image"]["width"])
    height = int(a["height"] or sc["image"]["height"])

    # An empty scene.
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = int(a["samples"])
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.seed = int(a["seed"])
    cy.sampling_pattern = "SOBOL"  # the 3.4 default (Sobol-Burley)
    cy.max_bounces = 1024
    cy.volume_bounces = 1024
    cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = 0
    cy.transparent_max_bounces = 8
    cy.min_light_bounces = 0
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.blur_glossy = 0.0
    cy.volume_step_rate = float(a["step-rate"])
    cy.volume_max_steps = 4096
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.film_exposure = 1.0
    cy.use_auto_tile = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = int(a["threads"])
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.use_persistent_data = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "ZIP"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.filepath = a["out"]
    scene.render.use_file_extension = False

    # Black world: no environment light.
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    k = vec(a["rgb-scale"])
    kmax = max(k)
    if transmittance:  # radiance 1 in atmos's units
        bg.inputs["Color"].default_value = (k[0] / kmax, k[1] / kmax, k[2] / kmax, 1)
        bg.inputs["Strength"].default_value = kmax
    else:
        bg.inputs["Color"].default_value = (0, 0, 0, 1)
        bg.inputs["Strength"].default_value = 0.0
    scene.world = world

    # The volume: the VDB's frame is atmos's (y up) up to the offset; Blender is z up, so the
    # object turns by +90 degrees about x: (x, y, z) -> (x, -z, y).
    vol = bpy.data.volumes.new("cloud")
    vol.filepath = a["vdb"]
    vol.grids.load()
    names = [gr.name for gr in vol.grids]
    if "density" not in names:
        sys.exit("cycles_scene.py: the VDB has no 'density' grid (grids: %s)" % names)
    vol.render.space = "OBJECT"
    vol.render.step_size = 0.0  # automatic: the voxel size, divided by the step rate
    vol.render.clipping = 0.0
    vol.render.precision = "FULL"
    ob = bpy.data.objects.new("cloud", vol)
    scene.collection.objects.link(ob)
    ob.rotation_euler = (math.pi / 2, 0.0, 0.0)
    # --voxel-shift S --voxel-size V: move the grid by S voxels along each of its axes. Blender
    # 3.4 puts a VDB's voxel values half a voxel further along each grid axis than OpenVDB's
    # index-to-world transform, which atmos follows (docs/cycles.md): run.sh passes -0.5.
    vs = float(a["voxel-shift"]) * float(a.get("voxel-size", "0") or 0)
    off = vec(a["offset"])
    ob.location = to_blender([off[0] + vs, off[1] + vs, off[2] + vs])

    # Principled Volume with Color c, black Absorption Color, Density D:
    # sigma_s = D c, sigma_a = D (1 - c): sigma_t = D, albedo = c.
    mat = bpy.data.materials.new("medium")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    pv = nt.nodes.new("ShaderNodeVolumePrincipled")
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    pv.inputs["Color"].default_value = (albedo, albedo, albedo, 1)
    pv.inputs["Density"].default_value = sigma_t
    pv.inputs["Density Attribute"].default_value = "density"
    pv.inputs["Anisotropy"].default_value = g
    pv.inputs["Absorption Color"].default_value = (0, 0, 0, 1)
    pv.inputs["Emission Strength"].default_value = 0.0
    pv.inputs["Blackbody Intensity"].default_value = 0.0
    nt.links.new(pv.outputs["Volume"], out.inputs["Volume"])
    mat.cycles.volume_sampling = "MULTIPLE_IMPORTANCE"
    mat.cycles.volume_interpolation = "LINEAR"
    mat.cycles.homogeneous_volume = False
    vol.materials.append(mat)

    # The sun: direction towards it from elevation and azimuth (clockwise from north, atmos
    # -z, Blender +y). A sun lamp shines along its local -z.
    e = math.radians(sun_d["elevation_deg"])
    az = math.radians(sun_d["azimuth_deg"])
    d = Vector((math.sin(az) * math.cos(e), math.cos(az) * math.cos(e), math.sin(e)))
    E = sun_d["irradiance"]
    if isinstance(E, list):
        sys.exit("cycles_scene.py: give the sun's irradiance as one number (a flat spectrum)")
    lamp = bpy.data.lights.new("sun", "SUN")
    lamp.energy = 0.0 if transmittance else E * kmax
    lamp.color = (k[0] / kmax, k[1] / kmax, k[2] / kmax)
    lamp.angle = math.radians(sc.get("atmosphere", {}).get("sun_diameter_deg", 0.5))
    lamp.cycles.cast_shadow = True
    lamp.cycles.max_bounces = 1024
    lamp.cycles.use_multiple_importance_sampling = True
    lo = bpy.data.objects.new("sun", lamp)
    scene.collection.objects.link(lo)
    lo.rotation_euler = d.to_track_quat("Z", "Y").to_euler()

    # The camera: pinhole, vertical field of view, up = atmos +y = Blender +z.
    camd = bpy.data.cameras.new("camera")
    camd.type = "PERSP"
    camd.sensor_fit = "VERTICAL"
    camd.angle_y = math.radians(cam_d["fov_deg"])
    camd.clip_start = 0.1
    camd.clip_end = 1e6
    co = bpy.data.objects.new("camera", camd)
    scene.collection.objects.link(co)
    pos, look = to_blender(cam_d["position_m"]), to_blender(cam_d["look_at_m"])
    co.location = pos
    co.rotation_euler = (look - pos).to_track_quat("-Z", "Y").to_euler()
    scene.camera = co

    # Cycles' own breakdown (scene sync, path tracing) goes to stdout after the render.
    _cycles.enable_print_stats()
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    t1 = time.perf_counter()
    print("cycles-timing: samples %d total_s %.3f" % (cy.samples, t1 - t0), flush=True)


main()
