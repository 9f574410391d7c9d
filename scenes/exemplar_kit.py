"""StyLit's exemplar scene, "a sphere on a table" (Fišer et al. 2016, §8.3.1),
built in code inside Blender.

One sphere on a table plane, lit by the same area light as the demo scene
(scene_kit.KEY_LIGHT, same direction relative to the sphere), seen by a
closer camera from the demo camera's direction so that the sphere is large in
the frame and its cast shadow, the lit table and the far table edge with the
background behind it are all visible: every illumination effect the demo
frames contain, bar the blue box's colour.

    scene = exemplar_kit.build_exemplar_scene()
    exemplar_kit.render_exemplar(scene, out / "exemplar" / "guides.exr", (320, 240), 64)
"""
import scene_kit

# The passes the StyLit guides need (see tempera.stylit_guides).
EXEMPLAR_PASSES = ("Combined", "DiffDir", "DiffCol", "GlossDir", "GlossCol", "DiffInd")
SCENE_NAME = "Tempera exemplar"


def build_exemplar_scene(name=SCENE_NAME):
    """A new scene `name` holding the exemplar; returns it."""
    scene = scene_kit.new_scene(name)
    scene_kit.add_table(scene, half_x=1.6, half_y=1.1)  # as large as the demo table
    scene_kit.add_sphere(scene, (0.0, -0.1, scene_kit.SPHERE_RADIUS))
    scene_kit.add_key_light(scene, offset=(0.0, -0.1, 0.0))
    scene_kit.add_camera(scene, location=(0.0, -2.0, 1.05), target=(0.0, 0.05, 0.2), lens=42)
    scene_kit.set_world(scene)
    return scene


def render_exemplar(scene, path, resolution, samples):
    """Renders the exemplar's guide passes into the multilayer EXR `path`."""
    scene_kit.configure_render(scene, resolution, samples, EXEMPLAR_PASSES)
    scene.frame_start = scene.frame_end = 1
    return scene_kit.render_exr(scene, path, frame=1)
