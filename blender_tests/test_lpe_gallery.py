"""The validation gallery (scenes/lpe_gallery.py): every scene rendered by
Cycles with its Light Path passes and traced by Tempera at matched settings
(same bounce limits, caustics off as in the guide cache), compared buffer
by buffer after a small blur:

    FULL  = Combined             vs  L.*E
    LDE   = DiffDir x DiffCol    vs  LDE
    LSE   = GlossDir x GlossCol  vs  LSE
    LDDE  = DiffInd x DiffCol    vs  L.*DDE

over the pixels Cycles sees only geometry in (alpha > 0.99: silhouette
pixels also hold the world in the tracer's L.*E, not in Cycles' transparent
film). Figures:
* mean error: |mean(tracer) - mean(Cycles)| / mean(Cycles) of the luminance,
  at most MEAN_TOLERANCE = 5 %;
* correlation: Pearson's correlation of the blurred luminance images, at
  least CORRELATION_TOLERANCE = 0.98 (light in the right places).
A buffer Cycles leaves (nearly) empty, below 0.2 % of FULL's mean, must be as
empty in the tracer (its mean below 2 % of FULL's) and is not correlated.

FULL and LDDE are also compared object by object, over each object's pixels
(Cycles' Object Index pass), so that light wrong on one object and right on
average shows (issue 35: a backdrop 40 % too bright beside a darker sphere):
* FULL: mean error at most 5 %, correlation at least 0.97 unless the object
  is lit evenly (the standard deviation of its blurred FULL under 10 % of
  its mean: a flat wall's correlation is noise);
* LDDE: the difference of the means at most 2 % of the object's FULL mean
  (indirect light that would change how bright the object looks by more).
  Relative to LDDE itself, the small indirect light of glass and glossy
  objects is noise at the gallery's samples (15 % on the glass cube at 128
  samples, 2 % at 1024).
"""
import os
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "scenes"))
import lpe_gallery  # noqa: E402

# The exporter tells the tracer which Cycles renders the guides
# (compat.cycles_light_model, compat.cycles_closure_model: 3.x's or 4.0's
# lights, microfacets and Principled BSDF), so every scene must pass in
# Debian's 3.4 and in blender.org 4.2, 4.5 and 5.0.
SAMPLES = int(os.environ.get("GALLERY_SAMPLES", 128))  # Cycles and the tracer alike (override to study noise)
# Scenes whose LSE mean is still noise at 128 samples, in Cycles and the
# tracer alike, with the count each one gets (GALLERY_SAMPLES overrides all):
# - layer_weight, bounce_limits: a highlight smaller than a pixel (GGX
#   roughness 0.2 under the small key: two or three pixels hold half of the
#   buffer's light). Over seeds, 128 samples scatter the mean by 3-4 % in
#   Cycles 3.4, 4.2 and the tracer, single runs by up to 7 %; at 4096 the
#   tracer is within 1.2 % of Cycles (docs/lpe_guides.md, "Sub-pixel
#   highlights"). 16 x the samples: a quarter of the scatter.
# - principled_layers: its coat reflects the small light in a sharp
#   highlight; in Cycles 4 its LSE error is 5.7 % at 128 samples, 1.5 % at
#   256 and 2.1 % at 1024 (both renderers' 128-sample means are 4 % off their
#   converged values).
# - rough_glass: its sphere's own FULL (light through rough glass) correlates
#   0.957 with Cycles' at 128 samples in 3.4, 0.995 at 256.
SCENE_SAMPLES = {} if "GALLERY_SAMPLES" in os.environ else {
    "layer_weight": 16 * SAMPLES, "bounce_limits": 16 * SAMPLES, "principled_layers": 2 * SAMPLES,
    "rough_glass": 2 * SAMPLES}
MEAN_TOLERANCE = 0.05
CORRELATION_TOLERANCE = 0.98
BLUR = 2  # box radius in pixels: 5 x 5
BUFFERS = {"FULL": "L.*E", "LDE": "LDE", "LSE": "LSE", "LDDE": "L.*DDE"}
PASSES = {"Combined": "RGBA", "DiffDir": "RGB", "DiffInd": "RGB", "DiffCol": "RGB", "GlossDir": "RGB",
          "GlossCol": "RGB", "IndexOB": "X"}
OBJECT_BUFFERS = ("FULL", "LDDE")  # compared per object too
OBJECT_CORRELATION_TOLERANCE = 0.97
OBJECT_LDDE_TOLERANCE = 0.02  # of the object's FULL mean
MIN_OBJECT_CONTRAST = 0.1  # below it an object's correlation is not asserted (see object_failures)
MIN_OBJECT_PIXELS = 100  # smaller objects (of 4800 pixels) are left to the whole-image figures
LUMINANCE = np.array([0.2126, 0.7152, 0.0722], np.float32)
# Measured and not understood, so reported but not asserted (docs/lpe_guides.md, "Limitations"):
KNOWN_DEVIATIONS = {
    ("glass", "LSE"): "the tracer's reflections of lights in sharp glass are noisy at the gallery's samples "
                      "(reflection is sampled with probability F: the mean scatters 15 % over seeds at 128, "
                      "Cycles' 3-4 %); at 4096 samples it agrees within 0.6 % (3.4) and 1.2 % (4.2)",
    ("world_visibility", "LSE"): "a world invisible to glossy rays still reaches glossy lobes in Cycles 3.4 "
                                 "through light sampling (about 12 % of its visible LSE); the tracer leaves it "
                                 "out entirely",
    # What a light beyond its own Max Bounces still gives is the MIS share of
    # the BSDF rays that hit it, so it rests on Cycles' own pdfs (which lobe
    # it samples, which light it picks): under 5.0's default Principled
    # surface the tracer's is 22 % lower on the floor (0.14 % of its FULL; 4.5,
    # with the Diffuse default surface: 1.3 %).
    **({("light_max_bounces", "LDDE"): "the indirect light of a light beyond its Max Bounces (BSDF rays "
                                       "weighted by MIS) is 8 % lower than Cycles 5.0's under its default "
                                       "Principled surfaces; each object's LDDE within 0.14 % of its FULL"}
       if bpy.app.version >= (5, 0, 0) else {}),
}
# The same for one object's FULL, keyed (scene, object), in the Cycles that shows it.
KNOWN_OBJECT_DEVIATIONS = {
    ("rough_glass", "Sphere"): "Cycles 4 shows what is seen through the rough glass sphere 9 % brighter than "
                               "the tracer (4.2, 256 samples; 0.6 % in 3.4), while the whole image agrees within "
                               "0.8 %",
} if bpy.app.version >= (4, 0, 0) else {}


def samples_for(key):
    """The gallery's sample count for scene `key` (Cycles and the tracer alike)."""
    return SCENE_SAMPLES.get(key, SAMPLES)


def box_blur(image, radius=BLUR):
    """Mean over (2r + 1)^2 pixels, edges clamped."""
    out = image.astype(np.float64)
    for axis in (0, 1):
        padded = np.pad(out, [(radius, radius) if a == axis else (0, 0) for a in range(out.ndim)], mode="edge")
        c = np.cumsum(padded, axis=axis)
        c = np.concatenate([np.zeros_like(np.take(c, [0], axis=axis)), c], axis=axis)
        n = out.shape[axis]
        out = (np.take(c, range(2 * radius + 1, n + 2 * radius + 1), axis=axis) -
               np.take(c, range(0, n), axis=axis)) / (2 * radius + 1)
    return out


def masked_blur(image, mask):
    """Box blur of `image` over the pixels of `mask` only (background pixels,
    which the tracer's L.*E fills with the world and Cycles' transparent film
    leaves at 0, do not bleed in)."""
    m = mask.astype(np.float64)
    weight = box_blur(m)
    return np.where(weight > 0, box_blur(image * m) / np.maximum(weight, 1e-12), 0)


def compare(traced, reference, mask, full_mean):
    """(mean error, correlation, reference mean, traced mean) of luminance over `mask`;
    correlation is None for a buffer Cycles leaves empty."""
    t, r = traced @ LUMINANCE, reference @ LUMINANCE
    t_mean, r_mean = float(t[mask].mean()), float(r[mask].mean())
    if r_mean < 0.002 * full_mean:
        return None, None, r_mean, t_mean
    bt, br = masked_blur(t, mask)[mask], masked_blur(r, mask)[mask]
    # A constant image (e.g. the tracer's all black) has no correlation: 0, which fails.
    correlation = float(np.corrcoef(bt, br)[0, 1]) if bt.std() > 0 and br.std() > 0 else 0.0
    return abs(t_mean - r_mean) / r_mean, correlation, r_mean, t_mean


def cycles_buffers(scene, tmp, samples=SAMPLES, seed=0):
    """Cycles' buffers of the scene, with the guide cache's render settings;
    "index" is each pixel's object, "objects" maps the objects' names to it."""
    from tempera.blender import guide_render

    objects = {}
    for i, obj in enumerate(sorted((o for o in scene.objects if o.type == "MESH"), key=lambda o: o.name)):
        obj.pass_index = i + 1
        name = obj.name.split(".")[0]  # "Sphere.003" -> "Sphere": the gallery's own names
        objects[obj.name if name in objects else name] = i + 1
    layer = scene.view_layers[0]
    guide_render._configure(scene, layer, samples, PASSES, seed)
    path = guide_render._render(scene, Path(tmp) / f"{scene.name}.exr", 1)
    p = guide_render._read_passes(path, layer.name, PASSES)
    rgb = {k: v[:, :, :3] for k, v in p.items()}
    return {"FULL": rgb["Combined"], "LDE": rgb["DiffDir"] * rgb["DiffCol"],
            "LSE": rgb["GlossDir"] * rgb["GlossCol"], "LDDE": rgb["DiffInd"] * rgb["DiffCol"],
            "alpha": p["Combined"][:, :, 3], "index": np.rint(p["IndexOB"][:, :, 0]), "objects": objects}


def traced_buffers(scene, samples=SAMPLES, seed=0, edit=None):
    """The tracer's buffers at the scene's current settings (after
    cycles_buffers: caustics off, as Cycles rendered); `edit(scene_dict)`
    may change the exported scene first."""
    from tempera.blender.scene_export import evaluated_depsgraph, export_scene, path_settings
    from tempera.tracer.lpe import trace_lpe

    size = (scene.render.resolution_x, scene.render.resolution_y)
    scene_dict, warnings = export_scene(scene, evaluated_depsgraph(scene, scene.view_layers[0], 1), size)
    if edit:
        edit(scene_dict)
    images, alpha = trace_lpe(scene_dict, list(BUFFERS.values()), samples=samples, seed=seed,
                              **path_settings(scene))
    return dict(zip(BUFFERS, images), alpha=alpha), warnings


def gallery_figures(cycles, traced, mask=None, buffers=BUFFERS):
    """({buffer: compare's figures}, FULL's mean) over `mask` (default: every
    pixel Cycles sees only geometry in)."""
    mask = cycles["alpha"] > 0.99 if mask is None else mask
    full_mean = float((cycles["FULL"] @ LUMINANCE)[mask].mean())
    return {b: compare(traced[b], cycles[b], mask, full_mean) for b in buffers}, full_mean


def object_figures(cycles, traced):
    """{object name: (figures, FULL's mean, FULL's contrast)}: gallery_figures
    of OBJECT_BUFFERS over that object's pixels, and the spread of its blurred
    Cycles FULL (standard deviation over mean)."""
    geometry = cycles["alpha"] > 0.99
    out = {}
    for name, index in cycles["objects"].items():
        mask = geometry & (cycles["index"] == index)
        if mask.sum() >= MIN_OBJECT_PIXELS:
            figures, full_mean = gallery_figures(cycles, traced, mask, OBJECT_BUFFERS)
            blurred = masked_blur(cycles["FULL"] @ LUMINANCE, mask)[mask]
            out[name] = figures, full_mean, float(blurred.std() / blurred.mean())
    return out


def object_failures(cycles, traced, label):
    """Prints each object's FULL and LDDE figures; returns the failures'
    descriptions (tolerances in the module's docstring)."""
    failures = []
    for name, (figures, full_mean, contrast) in object_figures(cycles, traced).items():
        # An evenly lit object has no light to put in the wrong place: its
        # correlation is noise, its mean still counts.
        correlation_tolerance = OBJECT_CORRELATION_TOLERANCE if contrast >= MIN_OBJECT_CONTRAST else -1
        print(f"{label} {name}: FULL contrast {contrast:.3f}")
        known = {"FULL": KNOWN_OBJECT_DEVIATIONS[label, name]} if (label, name) in KNOWN_OBJECT_DEVIATIONS else ()
        failures += figure_failures({"FULL": figures["FULL"]}, full_mean, f"{label} {name}", correlation_tolerance,
                                    known)
        _, _, r_mean, t_mean = figures["LDDE"]
        shift = abs(t_mean - r_mean) / full_mean
        print(f"{label} {name} LDDE: Cycles {r_mean:.4g}, tracer {t_mean:.4g}: {100 * shift:.2f} % of its FULL")
        if shift > OBJECT_LDDE_TOLERANCE:
            failures.append(f"{label} {name} LDDE: {100 * shift:.1f} % of its FULL")
    return failures


def figure_failures(figures, full_mean, label, correlation_tolerance=CORRELATION_TOLERANCE, known=()):
    """Prints each buffer's figures; returns the failures' descriptions."""
    failures = []
    for buffer, (error, correlation, r_mean, t_mean) in figures.items():
        if error is None:
            print(f"{label} {buffer}: empty in Cycles ({r_mean:.4g}), tracer {t_mean:.4g}")
            if t_mean > 0.02 * full_mean:
                failures.append(f"{label} {buffer}: Cycles empty, tracer mean {t_mean:.4g}")
            continue
        print(f"{label} {buffer}: mean error {error:.4f}, correlation {correlation:.4f} "
              f"(Cycles {r_mean:.4g}, tracer {t_mean:.4g})")
        if buffer in known:
            print(f"{label} {buffer}: known deviation, not asserted: {known[buffer]}")
            continue
        if not (error <= MEAN_TOLERANCE and correlation >= correlation_tolerance):
            failures.append(f"{label} {buffer}: mean error {error:.4f}, correlation {correlation:.4f}")
    return failures


def rendered_and_traced(key, tmp, edit=None):
    """(Cycles' buffers, the tracer's, the exporter's warnings) of gallery
    scene `key` at its samples; `edit` as traced_buffers takes it."""
    scene = lpe_gallery.build(key)
    try:
        cycles = cycles_buffers(scene, tmp, samples_for(key))
        traced, warnings = traced_buffers(scene, samples_for(key), edit=edit)
    finally:
        lpe_gallery.remove(scene)
    return cycles, traced, warnings


def all_failures(cycles, traced, label):
    """The whole image's failures and each object's, nothing known."""
    figures, full_mean = gallery_figures(cycles, traced)
    return figure_failures(figures, full_mean, label) + object_failures(cycles, traced, label)


@pytest.mark.parametrize("key", list(lpe_gallery.SCENES))
def test_gallery_scene_matches_cycles(key, tmp_path):
    cycles, traced, warnings = rendered_and_traced(key, tmp_path)
    known = {b: reason for (k, b), reason in KNOWN_DEVIATIONS.items() if k == key}
    figures, full_mean = gallery_figures(cycles, traced)
    failures = figure_failures(figures, full_mean, key, known=known)
    failures += object_failures(cycles, traced, key)
    print(f"{key} warnings: {warnings}")
    assert not failures, f"{key}: " + "; ".join(failures)


def test_gallery_figures_catch_a_wrong_material(tmp_path):
    """The figures are not lenient: the Mix Shader sphere traced as what the
    exporter used to make of it (a diffuse surface of a viewport white) fails them."""
    def white_diffuse_sphere(scene_dict):
        mixed = [i for i, m in enumerate(scene_dict["materials"]) if len(m["closures"]) == 2]
        assert len(mixed) == 1  # the sphere's Mix Shader: a diffuse and a glossy closure
        scene_dict["materials"][mixed[0]] = {"base_color": np.full(3, 0.8, np.float32)}

    cycles, traced, _ = rendered_and_traced("mix_glossy_diffuse", tmp_path, white_diffuse_sphere)
    figures, _ = gallery_figures(cycles, traced)
    failing = [b for b, (e, c, _, _) in figures.items()
               if e is not None and not (e <= MEAN_TOLERANCE and c >= CORRELATION_TOLERANCE)]
    print(f"wrong material: failing buffers {failing}")
    assert {"FULL", "LDE"} <= set(failing)


@pytest.mark.parametrize("key, setting", [("light_max_bounces", "max_bounces"),
                                          ("light_without_mis", "multiple_importance")])
def test_gallery_figures_catch_an_ignored_light_setting(key, setting, tmp_path):
    """The scenes of the lights' own Max Bounces and Multiple Importance fail
    when the tracer is not told them (as before issue 35)."""
    def forget(scene_dict):
        for light in scene_dict["lights"]:
            light.pop(setting)

    cycles, traced, _ = rendered_and_traced(key, tmp_path, forget)
    failures = all_failures(cycles, traced, key)
    print(f"{key} without {setting}: {failures}")
    assert failures


def test_gallery_figures_catch_the_other_oren_nayar(tmp_path):
    """Rough Diffuse BSDFs traced as the other Cycles renders them (3.x's
    Fujii form in 4.3+, 4.3's energy-preserving one before) fail the figures."""
    def other(scene_dict):
        model = scene_dict["closure_model"]
        model["energy_preserving_oren_nayar"] = not model["energy_preserving_oren_nayar"]

    cycles, traced, _ = rendered_and_traced("diffuse_roughness", tmp_path, other)
    failures = all_failures(cycles, traced, "diffuse_roughness")
    print(f"the other Oren-Nayar: {failures}")
    assert failures


def test_pixel_filter_matches_cycles_per_pixel(tmp_path):
    """Cycles' Blackman-Harris pixel filter (its default, width 1.5, spread
    over 3 pixels): the tracer with the scene's filter agrees pixel by pixel
    (RMS, relative to the mean) far better than with a box of one pixel."""
    from tempera.blender.scene_export import evaluated_depsgraph, export_scene, path_settings
    from tempera.tracer.lpe import trace_lpe

    scene = lpe_gallery.build("spot")  # sharp shadow edges and the cone's rim
    try:
        cycles = cycles_buffers(scene, tmp_path, samples=256)
        size = (scene.render.resolution_x, scene.render.resolution_y)
        scene_dict, _ = export_scene(scene, evaluated_depsgraph(scene, scene.view_layers[0], 1), size)
        settings = path_settings(scene)
        assert (settings["pixel_filter"], settings["filter_width"]) == ("blackman_harris", 1.5)
        (filtered,), _ = trace_lpe(scene_dict, ["LDE"], samples=256, **settings)
        (boxed,), _ = trace_lpe(scene_dict, ["LDE"], samples=256, **dict(settings, pixel_filter="box",
                                                                         filter_width=1.0))
    finally:
        lpe_gallery.remove(scene)
    reference = cycles["LDE"] @ LUMINANCE

    def rms(image):
        return float(np.sqrt(np.mean((image @ LUMINANCE - reference) ** 2)) / reference.mean())

    print(f"pixel filter: RMS {rms(filtered):.4f} with Cycles' filter, {rms(boxed):.4f} with a box")
    assert rms(filtered) <= 0.02 and rms(boxed) >= 2 * rms(filtered)
