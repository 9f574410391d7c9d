"""The fluid_velocity guide on a baked Mantaflow smoke domain: a flow slab
across the domain emits smoke with an initial velocity of +x, seen by an orthographic camera
looking along +y (world x is screen x). Cycles' Vector pass is zero on the
smoke; fluid_velocity must point along +x with the calibrated magnitude."""
import functools
import subprocess
import sys

import bpy
import numpy as np
import pytest
from guide_scene import cube_mesh

FLOW_SPEED = 6.0  # m/s, +x
FPS = 24
SIZE = (64, 40)
ORTHO_SCALE = 5.0  # metres across the image
BAKED = range(1, 7)
FRAMES = [4, 5]
GUIDE_PARAMS = {"samples": 4, "ld12e_samples": 1, "masks": "none"}


# A one-frame bake of an 8-cell smoke domain, in a separate process: PyPI's
# bpy 4.2 / 4.5 / 5.0 ship Mantaflow without a working solver (its script
# fails with "'LevelsetGrid' object has no attribute 'setConst'" and the
# process aborts), so the bake is tried where a crash cannot take pytest down.
PROBE = """
import bpy, tempfile
bpy.ops.mesh.primitive_cube_add()
domain = bpy.context.object
fluid = domain.modifiers.new("Fluid", "FLUID")
fluid.fluid_type = "DOMAIN"
s = fluid.domain_settings
s.domain_type, s.resolution_max, s.cache_type = "GAS", 8, "ALL"
s.cache_directory = tempfile.mkdtemp()
s.cache_frame_start = s.cache_frame_end = 1
with bpy.context.temp_override(object=domain, active_object=domain):
    assert bpy.ops.fluid.bake_all() == {"FINISHED"}
print("MANTAFLOW WORKS")
"""


@functools.lru_cache(maxsize=None)  # one probe per run
def mantaflow_problem():
    """None if this Blender can bake a fluid, else what went wrong."""
    if bpy.app.binary_path:  # a Blender executable
        command = [bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr", PROBE]
    else:  # the bpy module: the Python that imported it
        command = [sys.executable, "-c", PROBE]
    run = subprocess.run(command, capture_output=True, text=True, timeout=300)
    if run.returncode == 0 and "MANTAFLOW WORKS" in run.stdout:
        return None
    lines = [line for line in (run.stderr + run.stdout).splitlines() if "Error" in line] or ["no output"]
    return f"exit code {run.returncode}: {lines[0].strip()}"


def skip_without_mantaflow():
    problem = mantaflow_problem()
    if problem:
        pytest.skip(f"Blender {bpy.app.version_string} cannot simulate fluids (its Mantaflow fails a "
                    f"one-frame bake: {problem})")


def _smoke_material():
    material = bpy.data.materials.new("FluidVelocitySmoke")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    for node in list(nodes):
        if node.type != "OUTPUT_MATERIAL":
            nodes.remove(node)
    volume = nodes.new("ShaderNodeVolumePrincipled")
    volume.inputs["Density"].default_value = 20.0  # thick enough for alpha > 0.1 over the plume
    output = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
    material.node_tree.links.new(volume.outputs[0], output.inputs["Volume"])
    return material


def _scene_with_camera(name):
    """A new scene of SIZE at FPS seen by an orthographic camera ORTHO_SCALE
    wide that looks along +y with z up: world x is screen x, z is screen up."""
    scene = bpy.data.scenes.new(name)
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    camera = bpy.data.objects.new(f"{name}Camera", bpy.data.cameras.new(f"{name}Camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = ORTHO_SCALE
    camera.location = (0.0, -10.0, 0.0)
    camera.rotation_euler = (np.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene


def _remove_scene(scene):
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj)
    bpy.data.scenes.remove(scene)


def _add_cube(scene, name, size, location):
    obj = bpy.data.objects.new(name, cube_mesh(name, size))
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def _domain(scene, name, kind, resolution, cache_dir):
    """A 4 x 2 x 2 m fluid domain centred on the origin, baked frames BAKED
    into cache_dir: (object, domain settings)."""
    domain = _add_cube(scene, name, 2.0, (0, 0, 0))
    domain.scale = (2.0, 1.0, 1.0)
    fluid = domain.modifiers.new("Fluid", "FLUID")
    fluid.fluid_type = "DOMAIN"
    settings = fluid.domain_settings
    settings.domain_type = kind
    settings.resolution_max = resolution
    settings.cache_directory = cache_dir
    settings.cache_type = "ALL"
    settings.cache_frame_start, settings.cache_frame_end = BAKED.start, BAKED.stop - 1
    return domain, settings


def _flow(scene, name, kind, velocity, size, location):
    """A cube that emits `kind` once, at the first frame, with an initial `velocity` (m/s)."""
    flow = _add_cube(scene, name, size, location)
    flow.hide_render = True
    emitter = flow.modifiers.new("Fluid", "FLUID")
    emitter.fluid_type = "FLOW"
    fs = emitter.flow_settings
    fs.flow_type = kind
    fs.flow_behavior = "GEOMETRY"  # one puff at the first frame, then it drifts
    fs.use_initial_velocity = True
    fs.velocity_coord = velocity
    return flow


def build_smoke_scene(cache_dir):
    scene = _scene_with_camera("FluidVelocityScene")
    scene.frame_start, scene.frame_end = BAKED.start, BAKED.stop - 1

    domain, settings = _domain(scene, "SmokeDomain", "GAS", 24, cache_dir)
    domain.data.materials.append(_smoke_material())
    settings.alpha = settings.beta = 0.0  # no buoyancy: the smoke keeps the flow's direction
    settings.vorticity = 0.0
    settings.use_dissolve_smoke = False
    # Open at the ends along x (the inflow leaves, no back-pressure), walls along it: a channel.
    for side, wall in (("left", False), ("right", False), ("front", True), ("back", True), ("top", True),
                       ("bottom", True)):
        setattr(settings, f"use_collision_border_{side}", wall)

    # A slab across the channel, emitted once: a puff in plug flow, uniform +x
    # (a small emitter's smoke would spread sideways, a steady inflow's
    # alpha would grow ahead of the fluid as density piles up behind).
    flow = _flow(scene, "SmokeFlow", "SMOKE", (FLOW_SPEED, 0.0, 0.0), 1.0, (-1.3, 0, 0))
    flow.scale = (1.2, 2.2, 2.2)
    return scene, domain


def _bake(scene, domain):
    layer = scene.view_layers[0]
    with bpy.context.temp_override(scene=scene, view_layer=layer, object=domain, active_object=domain):
        result = bpy.ops.fluid.bake_all()
    assert result == {"FINISHED"}, f"fluid.bake_all returned {result}"


def _baked_guides(tmp, build, frames):
    """The scene `build(cache_dir)` makes, baked, and its guides of `frames` in tmp/guides."""
    from tempera.blender.guide_render import render_guides

    skip_without_mantaflow()
    scene, domain = build(str(tmp / "fluid_cache"))
    _bake(scene, domain)
    report = render_guides(scene, frames, tmp / "guides", GUIDE_PARAMS)
    return {"scene": scene, "domain": domain, "cache": tmp / "guides", "report": report}


@pytest.fixture(scope="module")
def smoke(tmp_path_factory):
    baked = _baked_guides(tmp_path_factory.mktemp("fluid_velocity"), build_smoke_scene, FRAMES)
    yield baked
    _remove_scene(baked["scene"])


def _frame(smoke, f):
    from tempera.app import guide_cache

    return guide_cache.read_frame(smoke["cache"], f, ["alpha", "velocity_forward", "fluid_velocity"])


def test_the_guide_is_written_for_a_smoke_scene(smoke):
    from tempera.app import guide_cache

    assert smoke["report"]["rendered"] == FRAMES
    assert "fluid_velocity" in guide_cache.read_manifest(smoke["cache"])["guides"]


def test_fluid_velocity_points_along_the_flow_where_the_smoke_is(smoke):
    for f in FRAMES:
        guides = _frame(smoke, f)
        smoky = guides["alpha"] > 0.1
        assert smoky.sum() > 50, f"frame {f}: only {smoky.sum()} smoke pixels"
        v = guides["fluid_velocity"][smoky]
        angle = np.degrees(np.abs(np.arctan2(v[:, 1], v[:, 0])))
        assert angle.max() < 15.0, f"frame {f}: {np.mean(angle > 15):.1%} of the smoke is more than 15 deg off +x"
        assert np.all(guides["fluid_velocity"][guides["alpha"] <= 1e-3] == 0)


def _smoke_centroid(scene, frame):
    """Pixel position of the density-weighted centre of the smoke at `frame`,
    from the density grid alone (the velocity grid plays no part)."""
    from tempera.app import fluid_velocity as fv
    from tempera.blender import fluid_velocity as bfv
    from tempera.blender.scene_export import evaluated_depsgraph

    depsgraph = evaluated_depsgraph(scene, scene.view_layers[0], frame)
    points, _velocities, density = bfv.scene_fluid_samples(scene, depsgraph)
    centre = (points * density[:, None]).sum(axis=0) / density.sum()
    position, _ = fv.project(centre[None], bfv.world_to_clip(scene, depsgraph, SIZE), SIZE)
    return position[0]


def test_fluid_velocity_is_the_smokes_motion_per_frame(smoke):
    """The units (the calibration of Mantaflow's time): the smoke's centre of
    density moves by fluid_velocity from one frame to the next (p moves to
    p + F). Its speed is a share of the flow's: the pressure solve spreads the
    slab's impulse over the channel."""
    scene = smoke["scene"]
    moved = _smoke_centroid(scene, FRAMES[1]) - _smoke_centroid(scene, FRAMES[0])
    first = _frame(smoke, FRAMES[0])
    alpha = first["alpha"]
    guide = (first["fluid_velocity"] * alpha[:, :, None]).sum(axis=(0, 1)) / alpha.sum()
    assert guide[0] == pytest.approx(moved[0], rel=0.25), (guide, moved)
    assert abs(moved[1]) < 0.05 * moved[0]
    flow = FLOW_SPEED / FPS * SIZE[0] / ORTHO_SCALE  # the flow's speed in pixels per frame
    assert 0.1 * flow < moved[0] < flow, (moved, flow)


def test_the_vector_pass_is_blind_to_smoke(smoke):
    """Why the guide exists: Cycles' motion vectors are zero on the volume."""
    guides = _frame(smoke, FRAMES[0])
    smoky = guides["alpha"] > 0.1
    assert np.abs(guides["velocity_forward"][smoky]).max() < 1e-3


# --------------------------------------------------------------------------- liquid

LIQUID_FRAMES = [4, 5]


def build_liquid_scene(cache_dir):
    """A block of liquid thrown at +3 m/s along x, falling under gravity, in
    a 4 x 2 x 2 m domain of 32 cells, seen by the same camera."""
    scene = _scene_with_camera("FluidVelocityLiquid")
    domain, settings = _domain(scene, "LiquidDomain", "LIQUID", 32, cache_dir)
    settings.use_mesh = True
    settings.use_speed_vectors = True  # Blender 3.4 still caches no mesh velocities: the grid serves
    _flow(scene, "LiquidFlow", "LIQUID", (3.0, 0.0, 0.0), 0.6, (-1.2, 0, 0))
    return scene, domain


@pytest.fixture(scope="module")
def liquid(tmp_path_factory):
    baked = _baked_guides(tmp_path_factory.mktemp("fluid_velocity_liquid"), build_liquid_scene, LIQUID_FRAMES)
    yield baked
    _remove_scene(baked["scene"])


def _liquid_centre(scene, domain, frame):
    """Pixel position of the mean vertex of the liquid mesh at `frame`."""
    from tempera.app import fluid_velocity as fv
    from tempera.blender import fluid_velocity as bfv
    from tempera.blender.scene_export import evaluated_depsgraph

    depsgraph = evaluated_depsgraph(scene, scene.view_layers[0], frame)
    evaluated = domain.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    centre = np.mean([list(evaluated.matrix_world @ v.co) for v in mesh.vertices], axis=0)
    evaluated.to_mesh_clear()
    position, _ = fv.project(centre[None], bfv.world_to_clip(scene, depsgraph, SIZE), SIZE)
    return position[0]


def test_liquid_moves_by_its_fluid_velocity(liquid):
    """The liquid's mean vertex moves by the guide's mean over the liquid
    from one frame to the next, both along x (thrown) and y (falling); the
    Vector pass sees none of it."""
    from tempera.app import guide_cache

    scene, domain = liquid["scene"], liquid["domain"]
    moved = _liquid_centre(scene, domain, LIQUID_FRAMES[1]) - _liquid_centre(scene, domain, LIQUID_FRAMES[0])
    g = guide_cache.read_frame(liquid["cache"], LIQUID_FRAMES[0], ["alpha", "velocity_forward", "fluid_velocity"])
    seen = g["alpha"] > 0.5
    assert seen.sum() > 30
    mean = g["fluid_velocity"][seen].mean(axis=0)
    assert moved[0] > 1.0 and moved[1] > 0.3  # right and down (y down), so the test can tell
    np.testing.assert_allclose(mean, moved, rtol=0.15, atol=0.1)
    assert np.abs(g["velocity_forward"][seen]).max() < 1e-3


# --------------------------------------------------------------------------- particles (no Mantaflow needed)

PARTICLE_SPEED = 3.0  # m/s along +x
PARTICLE_FRAMES = [3, 4]


def build_particle_scene():
    """Small spheres emitted once at frame 1 from a plane facing +x, moving
    at PARTICLE_SPEED with no gravity, seen by the same camera."""
    scene = _scene_with_camera("FluidVelocityParticles")
    scene.use_gravity = False
    ball = _add_cube(scene, "ParticleBall", 0.25, (0.0, 30.0, 0.0))  # instanced; itself out of view
    emitter = _add_cube(scene, "ParticleEmitter", 1.0, (-1.8, 0.0, 0.0))
    emitter.scale = (0.01, 1.0, 1.0)
    emitter.show_instancer_for_render = False
    system = emitter.modifiers.new("Particles", "PARTICLE_SYSTEM").particle_system
    settings = system.settings
    settings.count, settings.frame_start, settings.frame_end, settings.lifetime = 40, 1, 1, 200
    settings.emit_from = "FACE"
    settings.normal_factor = 0.0
    settings.object_align_factor = (PARTICLE_SPEED, 0.0, 0.0)  # +x in world space
    settings.effector_weights.gravity = 0.0
    settings.render_type = "OBJECT"
    settings.instance_object = ball
    settings.particle_size = 1.0
    return scene


@pytest.fixture(scope="module")
def particles(tmp_path_factory):
    from tempera.blender.guide_render import render_guides

    tmp = tmp_path_factory.mktemp("fluid_velocity_particles")
    scene = build_particle_scene()
    report = render_guides(scene, PARTICLE_FRAMES, tmp / "guides", GUIDE_PARAMS)
    yield {"scene": scene, "cache": tmp / "guides", "report": report}
    _remove_scene(scene)


def test_particles_move_by_their_velocity_times_the_timestep(particles):
    """A particle moves by velocity * timestep (0.04 s) per frame, whatever
    the fps; Cycles' motion vectors of the instanced spheres say the same,
    which checks the convention (p moves to p + F) against velocity_forward."""
    from tempera.app import guide_cache

    assert "fluid_velocity" in guide_cache.read_manifest(particles["cache"])["guides"]
    expected = PARTICLE_SPEED * 0.04 * SIZE[0] / ORTHO_SCALE  # pixels per frame
    for f in PARTICLE_FRAMES:
        g = guide_cache.read_frame(particles["cache"], f, ["alpha", "velocity_forward", "fluid_velocity"])
        seen = g["alpha"] > 0.5
        assert seen.sum() > 20, f"frame {f}: only {seen.sum()} particle pixels"
        fluid = g["fluid_velocity"][seen]
        np.testing.assert_allclose(np.median(fluid, axis=0), [expected, 0.0], atol=0.1 * expected)
        np.testing.assert_allclose(np.median(g["velocity_forward"][seen], axis=0), np.median(fluid, axis=0),
                                   atol=0.1 * expected)
        assert np.all(g["fluid_velocity"][g["alpha"] <= 1e-3] == 0)
