"""The fluids of a scene as samples for the fluid_velocity guide (tempera.app.fluid_velocity).

    samples = scene_fluid_samples(scene, depsgraph)    # None if the scene has no fluids
    field = fluid_velocity_guide(scene, depsgraph, samples, alpha)

Sources, read from the EVALUATED objects only (the original object's fluid
grids crash Blender 3.4):
* gas domains (smoke, fire): every voxel centre with its velocity and
  density (FluidDomainSettings.velocity_grid, density_grid), over the grid's
  bounds, which are the evaluated domain mesh's (the adaptive domain's
  current box included);
* liquid domains: the vertices of the evaluated liquid mesh and their
  `velocity` attribute (the domain's Speed Vectors option) or, where that
  reads back as zeros (a baked cache in Blender 3.4), the domain's velocity
  grid at each vertex;
* emitter particle systems: the live particles' location and velocity.
Cycles' Vector pass is zero on volumes and about zero on liquid meshes, which
is why this guide exists (docs/guide_cache.md).
"""
import numpy as np

from ..app import fluid_velocity as fv


def _fluid_domain(obj):
    """The object's fluid domain settings, or None."""
    for modifier in obj.modifiers:
        if modifier.type == "FLUID" and modifier.fluid_type == "DOMAIN" and modifier.show_render:
            return modifier.domain_settings
    return None


def _emitters(obj):
    return [p for p in obj.particle_systems if p.settings.type == "EMITTER" and p.settings.render_type != "NONE"]


def fluid_objects(scene):
    """The rendered objects that carry a fluid domain or emitter particles."""
    return [obj for obj in scene.objects
            if not obj.hide_render and (_fluid_domain(obj) is not None or _emitters(obj))]


def frame_rate(scene):
    return scene.render.fps / scene.render.fps_base


def _matrix(matrix):
    return np.array([list(row) for row in matrix], np.float64)


def _bounds(mesh):
    co = np.zeros(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    return co.min(axis=0), co.max(axis=0)


def _grid(obj, settings, bounds, fps):
    return fv.DomainGrid(tuple(settings.domain_resolution), *bounds, _matrix(obj.matrix_world), fps,
                         settings.time_scale)


def _gas_samples(obj, settings, fps):
    velocity = np.array(settings.velocity_grid, np.float32)
    if min(settings.domain_resolution) < 1 or velocity.size == 0:
        return None  # not simulated at this frame (e.g. before the cache starts)
    corners = np.array([list(c) for c in obj.bound_box])  # the evaluated box: an adaptive domain's too
    grid = _grid(obj, settings, (corners.min(axis=0), corners.max(axis=0)), fps)
    upres = settings.noise_scale if settings.use_noise else 1  # the density is at the noise's resolution
    return fv.gas_domain_samples(velocity, np.array(settings.density_grid, np.float32), grid, upres)


def _liquid_samples(obj, settings, fps):
    mesh = obj.to_mesh()
    try:
        count = len(mesh.vertices)
        if count == 0:
            return None  # no liquid yet
        vertices = np.zeros(count * 3, np.float32)
        mesh.vertices.foreach_get("co", vertices)
        velocity = np.zeros(count * 3, np.float32)
        attribute = mesh.attributes.get("velocity")
        if attribute is not None:
            attribute.data.foreach_get("vector", velocity)
    finally:
        obj.to_mesh_clear()
    vertices = vertices.reshape(-1, 3)
    bounds = _bounds(obj.original.data)  # the domain's own mesh, not the liquid's
    if velocity.any():  # Speed Vectors, while simulating
        size = float((bounds[1] - bounds[0]).max())
        return fv.mesh_samples(vertices, velocity.reshape(-1, 3), _matrix(obj.matrix_world), size, fps,
                               settings.time_scale)
    grid_velocity = np.array(settings.velocity_grid, np.float32)
    if grid_velocity.size == 0:
        return None
    return fv.liquid_grid_samples(vertices, grid_velocity, _grid(obj, settings, bounds, fps))


def _particle_samples(system):
    alive = [p for p in system.particles if p.alive_state == "ALIVE"]
    if not alive:
        return None
    locations = np.array([list(p.location) for p in alive])
    velocities = np.array([list(p.velocity) for p in alive])
    return fv.particle_samples(locations, velocities, system.settings.timestep)


def scene_fluid_samples(scene, depsgraph):
    """(points, velocities per frame, weights) of every rendered fluid of the
    scene as `depsgraph` evaluates it now, or None if it has no fluid object."""
    objects = fluid_objects(scene)
    if not objects:
        return None
    fps = frame_rate(scene)
    parts = []
    for original in objects:
        obj = original.evaluated_get(depsgraph)
        settings = _fluid_domain(obj)
        if settings is not None:
            reader = _gas_samples if settings.domain_type == "GAS" else _liquid_samples
            parts.append(reader(obj, settings, fps))
        parts += [_particle_samples(system) for system in _emitters(obj)]
    return fv.merge_samples(*(p for p in parts if p is not None))


def world_to_clip(scene, depsgraph, size):
    """The scene camera's 4x4 world to clip matrix at `size` = (width, height)
    pixels: perspective or orthographic, lens shift and sensor fit included."""
    camera = scene.camera.evaluated_get(depsgraph)
    render = scene.render
    projection = camera.calc_matrix_camera(depsgraph, x=size[0], y=size[1], scale_x=render.pixel_aspect_x,
                                           scale_y=render.pixel_aspect_y)
    return _matrix(projection @ camera.matrix_world.inverted())


def fluid_velocity_guide(samples, clip, alpha):
    """The fluid_velocity guide (H, W, 2) of `samples` seen through `clip`
    (world_to_clip, taken at the same frame) inside the render's `alpha`."""
    height, width = alpha.shape
    points, velocities, weights = samples
    return fv.fluid_velocity(points, velocities, weights, clip, (width, height), alpha)
