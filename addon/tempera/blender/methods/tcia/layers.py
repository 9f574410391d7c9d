"""Layers of the coherent method (Scene.tempera.tcia_layers): collections
painted and synthesized separately (Bénard 2013 §4, Figs. 9 and 10), each
with its motion extrapolated into its background, then composited by depth
or in list order (native/src/methods/tcia/tcia_layers.cpp). The list in the panel and its
operators."""
import re

from bpy.types import Operator, UIList

from ....app import guide_cache
from .keyframes import remove_selected
from ...setting_paths import resolve_path


def layer_name(collection_name):
    """A folder-safe layer name (OUT/frames/layers/NAME/) for a collection."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", collection_name).strip(".") or "layer"


def layer_list(settings, frames=None):
    """[(name, mask guide, painting path or None, its own keys), ...] for
    tempera.methods.tcia.tcia.ShotJob, in list order (the first at the back when the
    order is 'given'); keys only of `frames` (first, last) when given."""
    from .keyframes import key_list

    listed = {layer.collection for layer in settings.tcia_layers}
    for key in settings.keyframes:
        if key.layer is not None and key.layer not in listed:
            raise ValueError(f"Keyframe {key.frame} is of the collection '{key.layer.name}', which is not in the "
                             "Layers list: add it there or clear the key's Layer.")

    out, names = [], set()
    for i, layer in enumerate(settings.tcia_layers):
        if layer.collection is None:
            raise ValueError(f"Layer {i + 1} has no collection: pick one or remove the layer.")
        name = layer_name(layer.collection.name)
        if name in names:
            raise ValueError(f"Two layers are named '{name}' (the collection '{layer.collection.name}' is in the "
                             "Layers list twice, or two collections differ only in characters a folder name "
                             "cannot have): remove or rename one.")
        names.add(name)
        painting = resolve_path(layer.painting, f"painting of layer '{name}'") if layer.painting.strip() else None
        keys = [k for k in key_list(settings, layer.collection) if frames is None or frames[0] <= k[0] <= frames[1]]
        out.append((name, guide_cache.mask_guide("CO", layer.collection.name), painting, keys))
    return out


class TEMPERA_UL_tcia_layers(UIList):
    """The layers: collection and painting."""

    def draw_item(self, _context, layout, _data, item, _icon, _active_data, _active_prop, _index=0, _flt_flag=0):
        row = layout.row(align=True)
        row.prop(item, "collection", text="", emboss=False, icon="OUTLINER_COLLECTION")
        if item.painting:
            row.label(text="", icon="IMAGE_DATA")


class TEMPERA_OT_add_tcia_layer(Operator):
    """Add a layer: a collection painted and synthesized on its own"""

    bl_idname = "tempera.add_tcia_layer"
    bl_label = "Add Layer"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        settings = context.scene.tempera
        layer = settings.tcia_layers.add()
        used = {l.collection for l in settings.tcia_layers if l.collection is not None}
        free = [c for c in context.scene.collection.children_recursive if c not in used]
        layer.collection = free[0] if free else None
        settings.tcia_layer_index = len(settings.tcia_layers) - 1
        return {"FINISHED"}


class TEMPERA_OT_remove_tcia_layer(Operator):
    """Remove the selected layer from the list"""

    bl_idname = "tempera.remove_tcia_layer"
    bl_label = "Remove Layer"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and len(context.scene.tempera.tcia_layers) > 0

    def execute(self, context):
        remove_selected(context.scene.tempera, "tcia_layers", "tcia_layer_index")
        return {"FINISHED"}


CLASSES = (TEMPERA_UL_tcia_layers, TEMPERA_OT_add_tcia_layer, TEMPERA_OT_remove_tcia_layer)
