"""Temporal Noise as a method in the panel (Color Me Noisy, docs/noisy.md):
the scene's render boiled like hand-coloured animation, as in the paper's 3D
examples, a frame per step into Output Folder/noisy/frames (each frame
resumable; Esc stops within a frame and nothing of it is written). The
medium is a still (the Exemplar setting), else the first frame's render
under a paper grain, which the job makes (render_medium.hpp).
The same boiling after a light-path method's frames is the Temporal Noise
pass (tempera.blender.noise_pass)."""

from bpy.props import IntProperty

from ...methods.noisy import noisy
from ..layout import wide_prop
from ..properties import MEDIA_EXEMPLAR_KINDS
from ..setting_paths import resolve_path
from ..stylize_operator import MethodRun

MEDIUM = True
EXEMPLAR_MASKS = False
DEFAULT_LEVEL = noisy.TESTED_NOISE.index(2.2) + 1  # the paper's middle width

PROPERTIES = {
    "noisy_level": IntProperty(
        name="Noise",
        description="How coarse the boiling is: every frame re-synthesizes the medium's texture above a width f "
        "(steps 1-8: f = " + ", ".join(map(str, noisy.TESTED_NOISE)) + " px); below it the frames follow the "
        "render",
        default=DEFAULT_LEVEL, min=1, max=len(noisy.TESTED_NOISE)),
}


def draw(box, settings):
    """The noise step, its width f, the seed."""
    col = box.column()
    wide_prop(col, settings, "noisy_level")
    col.label(text=f"f = {noisy.noise_width(settings.noisy_level)} px; the render should look like the medium")
    col.prop(settings, "seed")


def medium(settings):
    """The medium's still: the Exemplar setting's, else "" (the job makes one
    from the render). ValueError for a sequence or a movie."""
    if not settings.media_exemplar.strip():
        return ""
    if settings.media_exemplar_kind != "STILL":
        label = next(n for k, n, _ in MEDIA_EXEMPLAR_KINDS if k == settings.media_exemplar_kind)
        raise ValueError(f"Temporal Noise takes a still sample of the medium: set Exemplar to Still (not {label}).")
    return resolve_path(settings.media_exemplar, "exemplar Still")


class NoisyRun(MethodRun):
    """Guides, then the registry's noisy job on the render."""

    folder = "noisy"
    method_label = "Temporal Noise"

    def __init__(self, scene, frames, mode="ANIMATION"):
        settings = scene.tempera
        options = {"noise": noisy.noise_width(settings.noisy_level), "seed": int(settings.seed)}
        # PNG whatever the Output Format: the frames are display-referred, as the render it boils.
        super().__init__(scene, frames, mode, medium(settings), options, "png")


def run(scene, frames, mode):
    """Stylize Animation's run, and Stylize Frame's (the method on that frame alone)."""
    return NoisyRun(scene, frames, mode)
