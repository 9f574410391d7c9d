"""Blender shader node trees as the light-path tracer's closures.

A small interpreter of the nodes Cycles evaluates, run once per material at
export time (docs/lpe_guides.md, "Materials"): it walks the tree from the
Material Output's Surface and returns the closures Cycles would build, each
as a dict of the tracer's scene format:

* shader nodes become closures (Diffuse, Glossy, Anisotropic, Glass,
  Refraction, Translucent, Transparent, Emission, Principled v1 and v2 by
  socket names); Mix Shader multiplies its first shader's closures by
  1 - fac and its second's by fac, Add Shader keeps both;
* factors that vary over the surface stay symbolic: a texture's value,
  Fresnel, Layer Weight (Fresnel or Facing) are evaluated by the tracer at
  each shading point;
* colours and scalars are constants, or image textures *baked* through the
  colour nodes that follow them (Mix/MixRGB, Invert, Gamma, Bright/Contrast,
  RGB to BW, Separate RGB/Color, Color Ramp, Math): the node is applied to
  every texel, and the tracer interpolates the result;
* texture coordinates are the render UV map, through UV Map, Texture
  Coordinate (UV) and Mapping nodes (folded into a 2D affine transform);
* node groups, reroutes and muted nodes are followed as Blender does.

Anything else gives a warning naming the node, and the closest supported
lobe with the node's own colour (never the viewport colour). No bpy import:
it reads the node objects it is given, so it runs wherever they exist.
"""
from __future__ import annotations

import math

import numpy as np

from ..tracer import scene_units

DEFAULT_GREY = (0.8, 0.8, 0.8)
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
IDENTITY_UV = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
SINGULAR_ROUGHNESS = 0.01


# --------------------------------------------------------------------------- values

class Value:
    """A colour or scalar: a constant, or texels of an image (RGBA float32,
    row 0 at the top) read at the UV transform `uv` (2 x 3), or (scalars only)
    a view-dependent node output (`kind` fresnel / layer_fresnel /
    layer_facing with parameter `param`). Scalars of a texture read `channel`
    (0..3, 4 = luminance)."""

    def __init__(self, const=None, texels=None, uv=IDENTITY_UV, channel=4, kind=None, param=0.0):
        self.const, self.texels, self.uv, self.channel, self.kind, self.param = \
            const, texels, uv, channel, kind, param

    @property
    def constant(self):
        return self.texels is None and self.kind is None

    def as_color(self):
        if self.kind is not None:
            return Value(const=np.full(3, 0.5))  # callers warn
        if self.texels is None:
            c = np.atleast_1d(np.asarray(self.const, np.float64))
            return Value(const=np.repeat(c[:1], 3) if c.size == 1 else c[:3])
        if self.channel == 4:
            return self
        t = self.texels[:, :, self.channel:self.channel + 1]
        return Value(texels=np.dstack([t, t, t, np.ones_like(t)]), uv=self.uv)

    def as_scalar(self):
        if self.kind is not None:
            return self
        if self.texels is None:
            c = np.atleast_1d(np.asarray(self.const, np.float64))
            return Value(const=float(c[0] if c.size == 1 else c[:3] @ LUMINANCE))
        if self.channel == 4:  # a colour texture as a value: its luminance, texel by texel
            return _scalar_texture(self.scalar_texels(), self.uv)
        return self

    def scalar_texels(self):
        """(H, W) texels of a textured scalar."""
        t = self.texels
        return t[:, :, :3] @ LUMINANCE.astype(np.float32) if self.channel == 4 else t[:, :, self.channel]

    def rgb_texels(self):
        return self.texels[:, :, :3]


def _scalar_texture(values, uv):
    v = np.asarray(values, np.float32)
    return Value(texels=np.dstack([v, v, v, np.ones_like(v)]), uv=uv, channel=0)


def _color_texture(rgb, uv, alpha=None):
    rgb = np.asarray(rgb, np.float32)
    a = np.ones(rgb.shape[:2], np.float32) if alpha is None else alpha
    return Value(texels=np.dstack([rgb, a]), uv=uv)


# --------------------------------------------------------------------------- the interpreter

class ShaderInterpreter:
    """Evaluates one node tree (material or world). `owner` names it in
    warnings; `images` caches image pixels across materials."""

    def __init__(self, owner, warnings, images):
        self.owner, self.warnings, self.images = owner, warnings, images

    def warn(self, message):
        text = f"{self.owner}: {message}"
        if text not in self.warnings:
            self.warnings.append(text)

    # ------------------------------------------------------------------ links

    def source(self, socket, ctx):
        """(output socket, its group context) feeding `socket`, through reroutes,
        groups and muted nodes; None if unlinked."""
        for _ in range(256):
            links = [link for link in socket.links if not getattr(link, "is_muted", False)
                     and getattr(link, "is_valid", True)] if socket.is_linked else []
            if not links:
                return None
            out = links[0].from_socket
            node = out.node
            kind = node.bl_idname
            if kind == "NodeReroute":
                socket = node.inputs[0]
                continue
            if node.mute:
                through = next((link.from_socket for link in node.internal_links if link.to_socket == out), None)
                if through is None:
                    return None
                socket = through
                continue
            if kind == "ShaderNodeGroup" and node.node_tree is not None:
                output = next((n for n in node.node_tree.nodes if n.bl_idname == "NodeGroupOutput"
                               and getattr(n, "is_active_output", True)), None)
                if output is None:
                    return None
                inner = _matching(output.inputs, out)
                if inner is None:
                    return None
                socket, ctx = inner, ctx + (node,)
                continue
            if kind == "NodeGroupInput":
                if not ctx:
                    return None
                group = ctx[-1]
                outer = _matching(group.inputs, out)
                if outer is None:
                    return None
                if not outer.is_linked:
                    return ("default", outer, ctx[:-1])
                socket, ctx = outer, ctx[:-1]
                continue
            return (out, ctx)
        self.warn("node links nest too deep; cut off")
        return None

    # ------------------------------------------------------------------ values

    def value(self, socket, ctx=()):
        """The Value of an input socket (its own default if unlinked)."""
        src = self.source(socket, ctx)
        if src is None:
            return _default(socket)
        if src[0] == "default":
            return _default(src[1])
        out, ctx = src
        return self.node_output(out, ctx)

    def color(self, socket, ctx=()):
        v = self.value(socket, ctx)
        if v.kind is not None:
            self.warn(f"'{socket.name}' is driven by a view-dependent node used as a colour; 0.5 grey is used.")
        return v.as_color()

    def scalar(self, socket, ctx=()):
        return self.value(socket, ctx).as_scalar()

    def constant_scalar(self, socket, ctx, what):
        v = self.scalar(socket, ctx)
        if not v.constant:
            self.warn(f"{what} is driven by a texture or view-dependent node; its mean is used.")
            if v.texels is not None:
                return float(np.mean(v.scalar_texels()))
            return 0.5
        return float(v.const)

    def node_output(self, out, ctx):
        node = out.node
        kind = node.bl_idname
        name = out.name
        inp = node.inputs
        if kind == "ShaderNodeRGB":
            return Value(const=np.array(out.default_value[:3], np.float64))
        if kind == "ShaderNodeValue":
            return Value(const=float(out.default_value))
        if kind == "ShaderNodeTexImage":
            return self.image_texture(node, out, ctx)
        if kind == "ShaderNodeFresnel":
            self._normal_ignored(node)
            return Value(kind="fresnel", param=self.constant_scalar(inp["IOR"], ctx, f"Fresnel '{node.name}' IOR"))
        if kind == "ShaderNodeLayerWeight":
            self._normal_ignored(node)
            blend = self.constant_scalar(inp["Blend"], ctx, f"Layer Weight '{node.name}' Blend")
            return Value(kind="layer_fresnel" if name == "Fresnel" else "layer_facing", param=blend)
        if kind in ("ShaderNodeMixRGB", "ShaderNodeMix"):
            return self.mix_color(node, out, ctx)
        if kind == "ShaderNodeInvert":
            fac, c = self.scalar(inp["Fac"], ctx), self.color(inp["Color"], ctx)
            return self.combine([fac, c], lambda f, x: x + (1 - 2 * x) * f, node)
        if kind == "ShaderNodeGamma":
            c, g = self.color(inp["Color"], ctx), self.scalar(inp["Gamma"], ctx)
            return self.combine([c, g], lambda x, y: np.where(x > 0, np.power(np.maximum(x, 0), y), x), node)
        if kind == "ShaderNodeBrightContrast":
            c, b, k = self.color(inp["Color"], ctx), self.scalar(inp["Bright"], ctx), self.scalar(inp["Contrast"], ctx)
            return self.combine([c, b, k], lambda x, bb, kk: np.maximum((1 + kk) * x + bb - kk / 2, 0), node)
        if kind == "ShaderNodeRGBToBW":
            return self.color(inp["Color"], ctx).as_scalar()
        if kind in ("ShaderNodeSeparateRGB", "ShaderNodeSeparateColor"):
            c = self.color(inp[0], ctx)
            if getattr(node, "mode", "RGB") != "RGB":
                self.warn(f"Separate Color '{node.name}' in {node.mode} mode is read as RGB.")
            index = {"R": 0, "G": 1, "B": 2, "Red": 0, "Green": 1, "Blue": 2}.get(name, 0)
            if c.texels is None:
                return Value(const=float(c.const[index]))
            return Value(texels=c.texels, uv=c.uv, channel=index)
        if kind == "ShaderNodeValToRGB":
            return self.color_ramp(node, out, ctx)
        if kind == "ShaderNodeMath":
            return self.math(node, ctx)
        if kind in ("ShaderNodeCombineRGB", "ShaderNodeCombineColor"):
            parts = [self.scalar(s, ctx) for s in list(inp)[:3]]
            if all(p.constant for p in parts):
                return Value(const=np.array([p.const for p in parts], np.float64))
        if kind == "ShaderNodeHueSaturation":
            c = self.color(inp["Color"], ctx)
            self.warn(f"Hue/Saturation '{node.name}' is not modelled by the light-path tracer; its input colour "
                      "passes through.")
            return c
        # Unknown: the socket's default-looking value, with a warning.
        self.warn(f"node '{node.name}' ({node.bl_label or kind}) is not modelled by the light-path tracer; "
                  f"its output '{name}' is taken as {_describe_default(out)}.")
        return _default(out)

    def _normal_ignored(self, node):
        normal = node.inputs.get("Normal")
        if normal is not None and normal.is_linked:
            self.warn(f"the Normal input of '{node.name}' is ignored (the shading normal is used).")

    def combine(self, values, fn, node):
        """Applies fn to constants, or texel by texel when one value is a texture."""
        textured = [v for v in values if v.texels is not None]
        if any(v.kind is not None for v in values):
            self.warn(f"'{node.name}' combines a view-dependent factor with colours; only the first input is kept.")
            return values[-1] if values[-1].kind is None else Value(const=0.5)
        if not textured:
            consts = [np.asarray(v.const, np.float64) for v in values]
            return Value(const=np.asarray(fn(*consts), np.float64))
        base = textured[0]
        h, w = base.texels.shape[:2]
        arrays = []
        for v in values:
            if v.texels is None:
                arrays.append(np.asarray(v.const, np.float32))
                continue
            if v.uv != base.uv or v.texels.shape[:2] != (h, w):
                if v.uv != base.uv:
                    self.warn(f"'{node.name}' combines textures with different coordinates; the second is read "
                              "at the first's.")
                v = _resample(v, h, w)
            # Colour textures read RGB; scalar ones (a channel) broadcast as one value per texel.
            arrays.append(v.rgb_texels() if v.channel == 4 else v.scalar_texels()[:, :, None])
        result = np.asarray(fn(*arrays), np.float32)
        if result.ndim == 3 and result.shape[2] == 3:
            return _color_texture(result, base.uv)
        return _scalar_texture(result.reshape(h, w), base.uv)

    def mix_color(self, node, out, ctx):
        if node.bl_idname == "ShaderNodeMix":
            data_type = getattr(node, "data_type", "RGBA")
            if data_type == "FLOAT":
                a, b, fac = self.scalar(node.inputs["A"], ctx), self.scalar(node.inputs["B"], ctx), \
                    self.scalar(node.inputs["Factor"], ctx)
                return self.combine([fac, a, b], lambda f, x, y: x + (y - x) * np.clip(f, 0, 1), node)
            sockets = [s for s in node.inputs if s.enabled]
            fac_socket = next(s for s in sockets if s.name == "Factor")
            a_socket = next(s for s in sockets if s.name == "A")
            b_socket = next(s for s in sockets if s.name == "B")
            clamp_result = getattr(node, "clamp_result", False)
            clamp_factor = getattr(node, "clamp_factor", True)
        else:
            fac_socket, a_socket, b_socket = node.inputs["Fac"], node.inputs["Color1"], node.inputs["Color2"]
            clamp_result, clamp_factor = node.use_clamp, True
        fac, a, b = self.scalar(fac_socket, ctx), self.color(a_socket, ctx), self.color(b_socket, ctx)
        blend = node.blend_type
        ops = {"MIX": lambda x, y: y, "MULTIPLY": lambda x, y: x * y, "ADD": lambda x, y: x + y,
               "SUBTRACT": lambda x, y: x - y, "SCREEN": lambda x, y: 1 - (1 - x) * (1 - y),
               "DIFFERENCE": lambda x, y: np.abs(x - y), "DARKEN": np.minimum, "LIGHTEN": np.maximum,
               "DIVIDE": lambda x, y: np.where(y != 0, x / np.where(y != 0, y, 1), 0)}
        if blend not in ops:
            self.warn(f"Mix '{node.name}' blend mode {blend} is not modelled; MIX is used.")
        op = ops.get(blend, ops["MIX"])

        def fn(f, x, y):
            f = np.clip(f, 0, 1) if clamp_factor else f
            if blend == "SCREEN":
                r = 1 - (1 - f + f * (1 - y)) * (1 - x)
            else:
                r = x + (op(x, y) - x) * f
            return np.clip(r, 0, 1) if clamp_result else r

        return self.combine([fac, a, b], fn, node)

    def color_ramp(self, node, out, ctx):
        fac = self.scalar(node.inputs["Fac"], ctx)
        ramp = node.color_ramp
        positions = np.linspace(0, 1, 257)
        table = np.array([ramp.evaluate(float(p)) for p in positions], np.float64)  # (257, 4)
        channel = 3 if out.name == "Alpha" else None

        def lookup(x):
            x = np.clip(np.asarray(x, np.float64), 0, 1)
            rgba = np.stack([np.interp(x, positions, table[:, k]) for k in range(4)], axis=-1)
            return rgba[..., 3] if channel == 3 else rgba[..., :3]

        if fac.kind is not None:
            self.warn(f"Color Ramp '{node.name}' is driven by a view-dependent factor; its middle is used.")
            fac = Value(const=0.5)
        if fac.texels is None:
            return Value(const=np.asarray(lookup(fac.const), np.float64))
        result = lookup(fac.scalar_texels()).astype(np.float32)
        return _scalar_texture(result, fac.uv) if channel == 3 else _color_texture(result, fac.uv)

    def math(self, node, ctx):
        sockets = [s for s in node.inputs if s.enabled]
        values = [self.scalar(s, ctx) for s in sockets]
        op = node.operation
        ops = {"ADD": lambda a, b: a + b, "SUBTRACT": lambda a, b: a - b, "MULTIPLY": lambda a, b: a * b,
               "DIVIDE": lambda a, b: np.where(b != 0, a / np.where(b != 0, b, 1), 0),
               "POWER": lambda a, b: np.where(a >= 0, np.power(np.maximum(a, 0), b), 0),
               "MINIMUM": np.minimum, "MAXIMUM": np.maximum,
               "MULTIPLY_ADD": lambda a, b, c: a * b + c}
        if op not in ops:
            self.warn(f"Math '{node.name}' operation {op} is not modelled; its first input passes through.")
            return values[0]
        fn = ops[op]
        arity = 3 if op == "MULTIPLY_ADD" else 2
        use_clamp = node.use_clamp
        return self.combine(values[:arity], lambda *a: np.clip(fn(*a), 0, 1) if use_clamp else fn(*a), node)

    # ------------------------------------------------------------------ textures

    def image_texture(self, node, out, ctx):
        image = node.image
        if image is None:
            self.warn(f"Image Texture '{node.name}' has no image; Cycles renders it magenta, the tracer black.")
            return Value(const=np.zeros(3)) if out.name == "Color" else Value(const=0.0)
        texels = self.images.pixels(image, self.owner, self.warnings)
        if texels is None:
            return Value(const=np.zeros(3)) if out.name == "Color" else Value(const=0.0)
        if node.projection != "FLAT":
            self.warn(f"Image Texture '{node.name}' projection {node.projection} is read as FLAT.")
        if node.extension not in ("REPEAT",):
            self.warn(f"Image Texture '{node.name}' extension {node.extension} is read as REPEAT.")
        uv = self.uv_transform(node.inputs["Vector"], ctx)
        if out.name == "Alpha":
            return Value(texels=texels, uv=uv, channel=3)
        return Value(texels=texels, uv=uv)

    def uv_transform(self, socket, ctx):
        """The 2 x 3 affine UV map feeding a texture's Vector input."""
        src = self.source(socket, ctx)
        if src is None or src[0] == "default":
            return IDENTITY_UV
        out, ctx = src
        node = out.node
        if node.bl_idname == "ShaderNodeUVMap" or (node.bl_idname == "ShaderNodeTexCoord" and out.name == "UV"):
            return IDENTITY_UV  # the render UV map (other named maps are not exported)
        if node.bl_idname == "ShaderNodeMapping":
            inner = self.uv_transform(node.inputs["Vector"], ctx)
            return _compose(self.mapping_matrix(node, ctx), inner)
        self.warn(f"texture coordinates from '{node.name}' ({node.bl_label}) are not modelled; the render UV map "
                  "is used.")
        return IDENTITY_UV

    def mapping_matrix(self, node, ctx):
        """Blender's Mapping node restricted to UV (x, y): 2 x 3 affine."""
        kind = node.vector_type
        loc = self._vector(node.inputs.get("Location"), ctx, (0, 0, 0))
        rot = self._vector(node.inputs.get("Rotation"), ctx, (0, 0, 0))
        scale = self._vector(node.inputs.get("Scale"), ctx, (1, 1, 1))
        if abs(rot[0]) > 1e-6 or abs(rot[1]) > 1e-6:
            self.warn(f"Mapping '{node.name}': rotation about X or Y is ignored for UVs.")
        c, s = math.cos(rot[2]), math.sin(rot[2])
        r = np.array([[c, -s], [s, c]])
        m = np.zeros((2, 3))
        if kind == "POINT":
            m[:, :2] = r @ np.diag(scale[:2])
            m[:, 2] = loc[:2]
        elif kind == "TEXTURE":
            inv = np.diag(1 / np.where(np.abs(scale[:2]) > 1e-12, scale[:2], 1e-12)) @ r.T
            m[:, :2] = inv
            m[:, 2] = -inv @ np.asarray(loc[:2])
        else:  # VECTOR / NORMAL: no translation
            m[:, :2] = r @ np.diag(scale[:2])
        return tuple(tuple(float(x) for x in row) for row in m)

    def _vector(self, socket, ctx, fallback):
        if socket is None:
            return np.array(fallback, np.float64)
        src = self.source(socket, ctx)
        if src is not None and src[0] != "default":
            self.warn(f"'{socket.name}' of a Mapping node is driven by nodes; its own value is used.")
        s = src[1] if src is not None and src[0] == "default" else socket
        return np.array(s.default_value[:3], np.float64)

    # ------------------------------------------------------------------ shaders

    def closures(self, socket, ctx=()):
        """Closures (tracer dicts, with "factors") feeding a shader socket."""
        src = self.source(socket, ctx)
        if src is None or src[0] == "default":
            return []
        out, ctx = src
        node = out.node
        kind = node.bl_idname
        inp = node.inputs
        if kind == "ShaderNodeMixShader":
            fac = self.scalar(inp[0], ctx)
            a, b = self.closures(inp[1], ctx), self.closures(inp[2], ctx)
            return _scaled(a, fac, invert=True) + _scaled(b, fac, invert=False)
        if kind == "ShaderNodeAddShader":
            return self.closures(inp[0], ctx) + self.closures(inp[1], ctx)
        if kind == "ShaderNodeBsdfDiffuse":  # Lambert, Oren-Nayar with a roughness
            self._normal_ignored(node)
            return [self._closure("diffuse", color=self.color(inp["Color"], ctx),
                                  roughness=self.scalar(inp["Roughness"], ctx))]
        if kind in ("ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic"):
            return [self.glossy(node, ctx)]
        if kind in ("ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction"):
            distribution = getattr(node, "distribution", "GGX")
            mapped = {"SHARP": "sharp", "BECKMANN": "beckmann", "GGX": "ggx"}.get(distribution)
            if mapped is None:
                self.warn(f"{node.bl_label} '{node.name}': distribution {distribution} is traced as GGX.")
                mapped = "ggx"
            self._normal_ignored(node)
            return [self._closure("glass" if kind == "ShaderNodeBsdfGlass" else "refraction",
                                  color=self.color(inp["Color"], ctx), distribution=mapped,
                                  roughness=self.scalar(inp["Roughness"], ctx),
                                  ior=self.constant_scalar(inp["IOR"], ctx, f"'{node.name}' IOR"))]
        if kind == "ShaderNodeBsdfTranslucent":
            self._normal_ignored(node)
            return [self._closure("translucent", color=self.color(inp["Color"], ctx))]
        if kind == "ShaderNodeBsdfTransparent":
            return [self._closure("transparent", color=self.color(inp["Color"], ctx))]
        if kind in ("ShaderNodeEmission", "ShaderNodeBackground"):
            strength = self.constant_scalar(inp["Strength"], ctx, f"'{node.name}' Strength")
            return [self._closure("emission", color=self.color(inp["Color"], ctx), weight=strength)]
        if kind == "ShaderNodeBsdfPrincipled":
            return self.principled(node, ctx)
        if kind == "ShaderNodeHoldout":
            self.warn(f"Holdout '{node.name}' is not modelled; it is black to the light-path tracer.")
            return []
        return self.fallback(node, ctx)

    def _closure(self, kind, color=None, weight=1.0, **params):
        c = {"type": kind, "weight": np.full(3, float(weight), np.float32), "factors": []}
        if color is not None:
            self._set_color(c, "color", color)
        for key, value in params.items():
            if isinstance(value, Value):
                self._set_scalar(c, key, value)
            elif value is not None:
                c[key] = value
        return c

    def _set_color(self, c, key, value):
        if value.texels is not None:
            c[f"{key}_texture"] = {"texels": value.texels, "uv": value.uv}
        else:
            c[key] = np.asarray(value.const, np.float32)[:3]

    def _set_scalar(self, c, key, value):
        if value.kind is not None:
            self.warn(f"'{key}' is driven by a view-dependent node; 0.5 is used.")
            c[key] = 0.5
        elif value.texels is not None:
            c[f"{key}_texture"] = {"texels": value.texels, "uv": value.uv, "channel": value.channel}
        else:
            c[key] = float(value.const)

    def glossy(self, node, ctx):
        inp = node.inputs
        distribution = getattr(node, "distribution", "GGX")
        mapped = {"SHARP": "sharp", "BECKMANN": "beckmann", "GGX": "ggx"}.get(distribution)
        if mapped is None:
            self.warn(f"{node.bl_label} '{node.name}': distribution {distribution} is traced as GGX.")
            mapped = "ggx"
        aniso = inp.get("Anisotropy")
        if aniso is not None and (aniso.is_linked or abs(float(aniso.default_value)) > 1e-6):
            self.warn(f"{node.bl_label} '{node.name}': anisotropy is not modelled (isotropic).")
        self._normal_ignored(node)
        return self._closure("glossy", color=self.color(inp["Color"], ctx), distribution=mapped,
                             roughness=self.scalar(inp["Roughness"], ctx))

    def principled(self, node, ctx):
        inp = node.inputs

        def get(*names):
            return next((inp[n] for n in names if n in inp), None)

        base = self.color(get("Base Color"), ctx)
        ior = self.constant_scalar(get("IOR"), ctx, f"Principled '{node.name}' IOR")
        metallic = self.constant_scalar(get("Metallic"), ctx, f"Principled '{node.name}' Metallic")
        v2 = "Specular IOR Level" in inp
        if v2:  # Blender 4: F0 from the IOR, scaled by the level (0.5 = as is)
            level = self.constant_scalar(inp["Specular IOR Level"], ctx, "Specular IOR Level")
            f0 = ((ior - 1) / (ior + 1)) ** 2 * 2 * level
            specular = f0 / 0.08  # what Principled v1 (the tracer's 3.x model) makes of it
        else:
            specular = self.constant_scalar(inp["Specular"], ctx, f"Principled '{node.name}' Specular")
        transmission = self.constant_scalar(get("Transmission Weight", "Transmission"), ctx,
                                            f"Principled '{node.name}' Transmission")
        roughness = self.scalar(get("Roughness"), ctx)
        rough = not roughness.constant or float(roughness.const) >= SINGULAR_ROUGHNESS
        if transmission > 0 and rough and not v2:  # v2's transmission is the tracer's rough glass
            self.warn(f"Principled '{node.name}': rough transmission is traced as smooth glass.")
        closure = self._closure("principled", color=base, metallic=metallic, specular=specular,
                                transmission=transmission, ior=ior, roughness=roughness)
        out = [closure]
        emission_color = get("Emission Color", "Emission")
        strength = self.constant_scalar(get("Emission Strength"), ctx, "Emission Strength") \
            if get("Emission Strength") is not None else 1.0
        emission = self.color(emission_color, ctx)
        if strength != 0 and (emission.texels is not None or np.any(np.asarray(emission.const) > 0)):
            out.append(self._closure("emission", color=emission, weight=strength))
        alpha = self.scalar(get("Alpha"), ctx)
        if not alpha.constant or float(alpha.const) < 1:
            out = _scaled(out, alpha, invert=False) + _scaled([self._closure("transparent", color=Value(
                const=np.ones(3)))], alpha, invert=True)
        if not v2:  # Principled v1 (Cycles 3.x): subsurface colours the diffuse, clearcoat is a GGX lobe
            subsurface = self.constant_scalar(inp["Subsurface"], ctx, "Subsurface")
            if subsurface > 0:
                ss_color = self.color(inp["Subsurface Color"], ctx)
                closure["subsurface"] = subsurface
                closure["subsurface_color"] = np.asarray(
                    ss_color.const if ss_color.texels is None else ss_color.texels[:, :, :3].reshape(-1, 3).mean(0),
                    np.float32)[:3]
                self.warn(f"Principled '{node.name}': subsurface scattering is traced as diffuse reflection of "
                          "the mixed colour (no light transport under the surface).")
            clearcoat = self.constant_scalar(inp["Clearcoat"], ctx, "Clearcoat")
            if clearcoat > 0:
                closure["clearcoat"] = clearcoat
                closure["clearcoat_roughness"] = self.constant_scalar(inp["Clearcoat Roughness"], ctx,
                                                                      "Clearcoat Roughness")
        if v2:
            self.principled_v2(node, closure, ctx)
        ignored = []
        for names, neutral in ((("Sheen Weight", "Sheen"), 0.0), (("Anisotropic",), 0.0),
                               (("Diffuse Roughness",), 0.0)):  # Blender 4.3+: traced as 0 (Lambertian)
            socket = get(*names)
            if socket is not None and (socket.is_linked or abs(float(socket.default_value) - neutral) > 1e-6):
                ignored.append(socket.name)
        if ignored:
            self.warn(f"Principled '{node.name}': {', '.join(ignored)} not modelled by the light-path tracer "
                      "(ignored).")
        if get("Normal") is not None and get("Normal").is_linked:
            self.warn(f"Principled '{node.name}': the normal map is ignored.")
        return out

    def principled_v2(self, node, closure, ctx):
        """Principled v2's own inputs (Blender 4.0+), which the tracer's
        Principled v2 model (closure_model "principled_v2") reads: the specular
        level and tint, the coat and the distribution. Subsurface scattering is
        traced as the Lambertian diffuse of the base colour."""
        inp = node.inputs
        name = f"Principled '{node.name}'"
        closure["specular_ior_level"] = self.constant_scalar(inp["Specular IOR Level"], ctx, f"{name} Specular IOR Level")
        closure["specular_tint"] = self._constant_color(inp["Specular Tint"], ctx, f"{name} Specular Tint")
        closure["multiscatter"] = getattr(node, "distribution", "GGX") == "MULTI_GGX"
        coat = self.constant_scalar(inp["Coat Weight"], ctx, f"{name} Coat Weight")
        if coat > 0:
            closure["clearcoat"] = coat  # the tracer's coat weight and roughness fields
            closure["clearcoat_roughness"] = self.constant_scalar(inp["Coat Roughness"], ctx, f"{name} Coat Roughness")
            closure["coat_ior"] = self.constant_scalar(inp["Coat IOR"], ctx, f"{name} Coat IOR")
            closure["coat_tint"] = self._constant_color(inp["Coat Tint"], ctx, f"{name} Coat Tint")
            if inp["Coat Normal"].is_linked:
                self.warn(f"{name}: the coat normal is ignored.")
        socket = inp["Subsurface Weight"]
        if socket.is_linked or float(socket.default_value) > 0:
            self.warn(f"{name}: subsurface scattering is traced as diffuse reflection of the base colour "
                      "(no light transport under the surface).")

    def _constant_color(self, socket, ctx, what):
        v = self.color(socket, ctx)
        if v.texels is not None:
            self.warn(f"{what} is driven by a texture; its mean is used.")
            return np.asarray(v.texels[:, :, :3].reshape(-1, 3).mean(0), np.float32)
        return np.asarray(v.const, np.float32)[:3]

    def fallback(self, node, ctx):
        """The closest lobe for a shader the tracer does not model, in its own colour."""
        inp = node.inputs
        color_socket = next((inp[n] for n in ("Color", "Base Color") if n in inp), None)
        color = self.color(color_socket, ctx) if color_socket is not None else Value(const=np.array(DEFAULT_GREY))
        label = node.bl_label or node.bl_idname
        if node.bl_idname == "ShaderNodeBsdfToon" and getattr(node, "component", "DIFFUSE") == "GLOSSY":
            lobe = self._closure("glossy", color=color, roughness=0.3, distribution="ggx")
            what = "a GGX glossy lobe (roughness 0.3)"
        else:
            lobe = self._closure("diffuse", color=color)
            what = "a diffuse lobe"
        self.warn(f"shader node '{node.name}' ({label}) is not modelled by the light-path tracer; it is traced as "
                  f"{what} of its own colour.")
        return [lobe]


# --------------------------------------------------------------------------- helpers

def _matching(sockets, socket):
    """The socket of `sockets` matching `socket` by identifier, else by name."""
    for s in sockets:
        if s.identifier == socket.identifier:
            return s
    return next((s for s in sockets if s.name == socket.name), None)


def _default(socket):
    value = getattr(socket, "default_value", None)
    if value is None:
        return Value(const=0.0)
    if hasattr(value, "__len__"):
        return Value(const=np.array(value[:], np.float64))
    return Value(const=float(value))


def _describe_default(socket):
    value = getattr(socket, "default_value", None)
    if value is None:
        return "0"
    if hasattr(value, "__len__"):
        return "(" + ", ".join(f"{v:.3g}" for v in value[:3]) + ")"
    return f"{value:.3g}"


def _resample(v, h, w):
    """Nearest-neighbour resampling of a texture value to h x w texels."""
    th, tw = v.texels.shape[:2]
    ys = (np.arange(h) * th // h).astype(int)
    xs = (np.arange(w) * tw // w).astype(int)
    return Value(texels=v.texels[ys][:, xs], uv=v.uv, channel=v.channel)


def _compose(outer, inner):
    """outer(inner(uv)) of two 2 x 3 affine maps."""
    a = np.vstack([np.array(outer), [0, 0, 1]])
    b = np.vstack([np.array(inner), [0, 0, 1]])
    m = a @ b
    return tuple(tuple(float(x) for x in row) for row in m[:2])


def _scaled(closures, fac, invert):
    """Closures weighted by a Mix Shader factor (1 - fac for the first shader)."""
    out = []
    for c in closures:
        c = dict(c, factors=list(c["factors"]))
        if fac.constant:
            f = min(max(float(fac.const), 0.0), 1.0)
            f = 1 - f if invert else f
            if f <= 0:
                continue
            c["weight"] = np.asarray(c["weight"], np.float32) * np.float32(f)
        elif fac.kind is not None:
            c["factors"].append({"kind": fac.kind, "value": float(fac.param), "invert": invert})
        else:
            c["factors"].append({"kind": "texture", "texture": {"texels": fac.texels, "uv": fac.uv,
                                                                "channel": fac.channel}, "invert": invert})
        out.append(c)
    return out


class ImageCache:
    """Linear RGBA float32 pixels of Blender images, row 0 at the top, read once per export."""

    def __init__(self):
        self._pixels = {}

    def pixels(self, image, owner, warnings):
        key = image.name
        if key not in self._pixels:
            self._pixels[key] = _read_image(image, owner, warnings)
        return self._pixels[key]


def _read_image(image, owner, warnings):
    width, height = image.size
    if width == 0 or height == 0:
        warnings.append(f"{owner}: image '{image.name}' has no pixels (missing file?); black is used.")
        return None
    channels = image.channels
    flat = np.empty(width * height * channels, np.float32)
    image.pixels.foreach_get(flat)
    pixels = flat.reshape(height, width, channels)[::-1]
    if channels >= 3:
        rgb = pixels[:, :, :3]
    else:
        rgb = np.repeat(pixels[:, :, :1], 3, axis=2)
    alpha = pixels[:, :, 3] if channels == 4 else np.ones((height, width), np.float32)
    space = image.colorspace_settings.name
    if not image.is_float and space == "sRGB":
        rgb = scene_units.srgb_to_linear(rgb)
    elif space not in ("sRGB", "Linear", "Linear Rec.709", "Non-Color", "Raw"):
        warnings.append(f"{owner}: image '{image.name}' is in colour space '{space}', which the light-path "
                        "tracer reads as is.")
    return np.ascontiguousarray(np.dstack([rgb, alpha]), np.float32)
