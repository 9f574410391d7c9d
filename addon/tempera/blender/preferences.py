"""Add-on preferences (Edit > Preferences > Add-ons > Tempera)."""
import functools

from bpy.props import StringProperty
from bpy.types import AddonPreferences

from .. import __version__
from ..app import cli

# The legacy add-on's module name; the extension registers the preferences under
# its own ("bl_ext.<repository>.tempera", see tempera.blender.register).
ADDON_ID = __package__.rpartition(".")[0]


@functools.lru_cache(maxsize=8)
def _cli_status(path, _mtime_ns):
    """(ok, text) for the CLI at `path`; cached per file version, draw() runs often."""
    try:
        return True, f"tempera {cli.cli_version(path, timeout=2.0)} at {path}"
    except cli.CliError as exc:
        return False, str(exc)


def cli_status(path_setting):
    try:
        path = cli.find_cli(path_setting)
        return _cli_status(str(path), path.stat().st_mtime_ns)
    except (cli.CliError, OSError) as exc:
        return False, str(exc)


class TemperaPreferences(AddonPreferences):
    bl_idname = ADDON_ID

    cli_path: StringProperty(
        name="CLI Path",
        description="The 'tempera' command line program for batch and render-farm jobs "
        "(optional; empty means 'tempera' on PATH)",
        subtype="FILE_PATH",
        default="",
    )

    def draw(self, _context):
        layout = self.layout
        layout.use_property_split = True
        layout.label(text=f"Tempera {__version__}")
        layout.prop(self, "cli_path")
        ok, text = cli_status(self.cli_path)
        layout.label(text=text, icon="CHECKMARK" if ok else "INFO")
