"""Temporal Noise (Color Me Noisy, docs/noisy.md) in the panel: the pass
that boils a light-path method's coherent frames into Output Folder/noisy
after they are made. Its Scene.tempera properties, its rows of the
Synthesis box, and its phase of a Stylize run, a frame per step
(tempera.methods.noisy.noisy.NoisySequence, resumable like the frames)."""
import os

import bpy
from bpy.props import BoolProperty, EnumProperty, IntProperty, PointerProperty, StringProperty

from ..app import settings as limits
from ..methods.noisy import noisy
from .layout import wide_prop
from .setting_paths import resolve_path

NOISY_DIR = "noisy"  # in the Output Folder

# Steps 1..8 are the paper's tested widths f.
PROPERTIES = {
    "noise_level": IntProperty(
        name="Temporal Noise",
        description="Hand-drawn 'boiling' after the coherent pass: every frame re-synthesizes the medium's "
        "texture above a width f (steps 1-8: f = " + ", ".join(map(str, noisy.TESTED_NOISE)) + " px; "
        "0 = off, the coherent frames as they are)",
        default=0, min=0, max=len(noisy.TESTED_NOISE),
    ),
    "noise_guided": BoolProperty(
        name="Guided Noise",
        description="Also keep the light-path guides while boiling, so thin strokes stay where the light "
        "matches the exemplar's (slower; docs/noisy.md)",
        default=False,
    ),
    "noise_map_source": EnumProperty(name="Noise Map", items=noisy.NOISE_MAP_SOURCES, default="NONE",
                                     description="Where the temporal noise goes"),
    "noise_map_image": StringProperty(name="Map Image", subtype="FILE_PATH",
                                      description="Greyscale image of the render's size: 0 coherent, 1 full noise"),
    "noise_map_object": PointerProperty(name="Map Object", type=bpy.types.Object,
                                        description="The object that boils (its mask guide)"),
    "noise_map_collection": PointerProperty(name="Map Collection", type=bpy.types.Collection,
                                            description="The collection that boils (its mask guide)"),
    "noise_map_guide": StringProperty(name="Map Guide",
                                      description="Name of a guide of the guide cache (an attribute or AOV)"),
}
MAP_FIELDS = {"IMAGE": "noise_map_image", "OBJECT": "noise_map_object", "COLLECTION": "noise_map_collection",
              "GUIDE": "noise_map_guide"}


def draw(box, settings):
    """The slider, its width f, Guided Noise and the map picker."""
    col = box.column()
    wide_prop(col, settings, "noise_level")
    if settings.noise_level == 0:
        return
    col.label(text=f"f = {noisy.noise_width(settings.noise_level)} px: frames boil into Output Folder/noisy")
    col.prop(settings, "noise_guided")
    col.prop(settings, "noise_map_source")
    field = MAP_FIELDS.get(settings.noise_map_source)
    if field:
        col.prop(settings, field)


class NoisePass:
    """The pass over one run's coherent frames: its NoisySequence, made once
    they exist, run a frame per step."""

    def __init__(self, args):
        self.args = args  # NoisySequence's keywords
        self.job = None
        self.results = []

    @classmethod
    def from_settings(cls, settings, out, config):
        """The pass of a run whose frames `config` makes (the StylizeJob
        keywords: style, out, frames, guides, seed, ...) into OUT/noisy, or
        None when Temporal Noise is off."""
        if settings.noise_level == 0:
            return None
        if config["format"] != "png":
            raise ValueError("Temporal Noise boils PNG frames: set Format to PNG.")
        image = settings.noise_map_image.strip()
        noise_map = noisy.noise_map_spec(
            settings.noise_map_source, resolve_path(image, "noise map image") if image else "",
            settings.noise_map_object.name if settings.noise_map_object else "",
            settings.noise_map_collection.name if settings.noise_map_collection else "",
            settings.noise_map_guide.strip())
        args = dict(exemplar=config["style"], reference=config["out"], frames=config["frames"],
                    out=os.path.join(out, NOISY_DIR), noise_map=noise_map, guides=config["guides"],
                    noise=noisy.noise_width(settings.noise_level), seed=config["seed"])
        if settings.noise_guided:  # guided noise: the exemplar's guides and the light-path weights
            args.update(exemplar_guides=config["exemplar_guides"], exemplar_frame=config.get("exemplar_frame"),
                        guide_weights=config["weights"], noise_guides=limits.PANEL_NOISE_GUIDES)
        return cls(args)

    @property
    def out(self):
        return self.args["out"]

    def step(self, index, progress=None):
        """Boils frames[index] (or skips it when current)."""
        if self.job is None:
            self.job = noisy.NoisySequence(**self.args)
        result = self.job.run_frame(index, progress)
        self.results.append(result)
        if bpy.app.background:  # the console is the only progress display
            print(f"Tempera: noisy frame {result['frame']} {result['status']} in {result['seconds']:.1f} s",
                  flush=True)

    def status_text(self):
        count = len(self.args["frames"])
        return f"Tempera: temporal noise, frame {min(len(self.results) + 1, count)}/{count} (Esc to stop)"

    def summary(self):
        made = sum(r["status"] == "made" for r in self.results)
        return f"{made} boiled (Temporal Noise) in {self.out}"
