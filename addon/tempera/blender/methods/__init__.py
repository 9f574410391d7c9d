"""Each method's side of the panel, one module per method, named as in the
registry (tempera.blender.methods.NAME for --method NAME). A
module holds what the panel, the operator and Scene.tempera need of its
method, so that nothing outside it names the method:

    PROPERTIES      Scene.tempera properties: name -> bpy property (added by add_properties)
    draw(box, settings)   the method's options in the Synthesis box
    run(scene, frames, mode)   its run (a tempera.blender.stylize_operator.StylizeRun)
                    for mode "ANIMATION" or "FRAME", or None for per-frame StyLit
    MEDIUM          True: the exemplar is a medium (a still, an image sequence
                    or a movie: the media_exemplar settings), not a painting
    EXEMPLAR_MASKS  True: the medium may come with a folder of mask frames
    CLASSES         optional: its property groups, lists and operators, to register

StyLit, the method without a module here, is the default: panels.py draws
its settings (draw_light_path_settings) and stylize_operator.StylizeRun runs it."""
import functools
import importlib

from bpy.props import BoolProperty, FloatProperty

from ...methods import registry


def side(method):
    """The module of `method` (the panel's item in capitals, or the
    registry's name), or None if it has none."""
    return _side(method.lower())


@functools.lru_cache(maxsize=None)  # the panel asks at every redraw; a missing module costs a path search
def _side(method):
    name = f"{__name__}.{method}"
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as error:
        if error.name != name:  # a module that is there but fails to import
            raise
        return None


def add_properties(settings_class):
    """Every method's PROPERTIES into the property group's annotations;
    call before the group is registered (Blender reads them then)."""
    for name in registry.names():
        module = side(name)
        if module is not None:
            settings_class.__annotations__.update(module.PROPERTIES)


def classes():
    """Every method's CLASSES (its property groups, lists and operators), in
    the registry's order: Blender registers them before Scene.tempera's group."""
    return tuple(cls for name in registry.names() for cls in getattr(side(name), "CLASSES", ()))


def tooltip(row):
    """A native option table row's help as a tooltip: a sentence."""
    return row["help"][0].upper() + row["help"][1:]


def table_properties(table, shown):
    """Properties of options the panel shows as they are: `shown` maps a
    property to (option of `table`, label, soft maximum); the default,
    limits and tooltip come from the option's row of the native table."""
    out = {}
    for prop, (option, label, soft_max) in shown.items():
        row = table[option]
        common = dict(name=label, default=row["default"], description=tooltip(row))
        out[prop] = (BoolProperty(**common) if isinstance(row["default"], bool)
                     else FloatProperty(min=row["min"], max=row["max"], soft_max=soft_max, **common))
    return out


def table_flags(settings, table, shown):
    """The values of `shown`'s properties (table_properties) by their
    command-line flags, as tempera.methods.registry.make_job takes them."""
    return {table[option]["flag"]: getattr(settings, prop) for prop, (option, _label, _soft) in shown.items()}
