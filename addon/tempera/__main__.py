"""The `tempera` command of the pip-installed wheel (console script), also
`python -m tempera`.

`tempera farm ...` and `tempera stylize --scheduler ADDRESS ...` run a shot on
a Dask cluster (tempera.app.farm); `tempera exemplar ...` writes one of the
project's own smoke/fire/ink exemplars (tempera.app.exemplar_cli), which `tempera stylize [--method M]`
also uses when the method has a default exemplar and --exemplar is left out; every other command is the
native batch CLI
(tempera_native/bin/tempera: synth, stylize, render-guides), run with this
package as the add-on that `render-guides` hands to Blender.
"""
import os
import sys
from pathlib import Path

PACKAGE_PARENT = Path(__file__).resolve().parent.parent


def native_cli():
    """Path of the native CLI: $TEMPERA_CLI, else the wheel's bin/tempera.
    Raises FileNotFoundError naming where it looked."""
    override = os.environ.get("TEMPERA_CLI")
    if override:
        path = Path(override)
    else:
        try:
            import tempera_native
        except ImportError as exc:
            raise FileNotFoundError(
                "the tempera CLI is not installed with this package (no tempera_native: "
                f"{exc}); set TEMPERA_CLI to build/bin/tempera") from exc
        path = tempera_native.cli()
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise FileNotFoundError(f"the tempera CLI '{path}' is missing or not executable")
    return path


def stylize_method(args):
    """The value of `--method M` or `--method=M` in stylize's arguments, or None."""
    for a, b in zip(args, args[1:] + [None]):
        if a == "--method":
            return b
        if a.startswith("--method="):
            return a.split("=", 1)[1]
    return None


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["farm"] or (argv[:1] == ["stylize"] and any(
            a == "--scheduler" or a.startswith("--scheduler=") for a in argv)):
        from .app.farm import main as farm_main

        return farm_main(argv[1:])
    if argv[:1] == ["stylize"] and len(argv) > 1:  # alone, it prints the overview
        from .app.exemplar_cli import with_default_exemplar
        from .methods import registry

        try:
            method = registry.find(stylize_method(argv[1:]) or registry.default_name())
            argv = ["stylize", *with_default_exemplar(argv[1:], method)]
        except (ValueError, OSError) as exc:  # an unknown method, an output folder that cannot be written
            print(f"tempera stylize: error: {exc}", file=sys.stderr)
            return 2 if isinstance(exc, ValueError) else 1
    if argv[:1] == ["exemplar"]:
        from .app.exemplar_cli import main as exemplar_main

        return exemplar_main(argv[1:])
    try:
        cli = native_cli()
    except FileNotFoundError as exc:
        print(f"tempera: {exc}", file=sys.stderr)
        return 1
    env = dict(os.environ)
    env.setdefault("TEMPERA_ADDON_PATH", str(PACKAGE_PARENT))
    os.execve(str(cli), [str(cli), *argv], env)


if __name__ == "__main__":
    sys.exit(main())
