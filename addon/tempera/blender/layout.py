"""Rows the panel's boxes share (panels.py, the methods' modules, the noise
pass): labels that fit the default Properties width."""
LABEL_FACTOR = 0.5  # share of a wide-label row given to its label


def wide_prop(layout, data, name, text=None):
    """A two-column row whose label column is wider than property split's
    40 %, for labels that would be cut at the default Properties width."""
    row = layout.split(factor=LABEL_FACTOR, align=True)
    label = row.column()
    label.alignment = "RIGHT"
    label.label(text=text if text is not None else data.bl_rna.properties[name].name)
    row.prop(data, name, text="")
