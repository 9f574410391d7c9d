"""The exit statuses of the package's own `tempera` subcommands (rigid,
exemplar), as the native CLI has them: 0 done, 2 bad input, 130 interrupted."""
import sys


def run_command(prog, run, cancelled="cancelled"):
    """Calls run() and returns its status; a ValueError or OSError is printed
    after `prog` and gives 2, Ctrl-C prints `cancelled` and gives 130."""
    try:
        return run()
    except KeyboardInterrupt:
        print(f"{prog}: {cancelled}", file=sys.stderr)
        return 130
    except (ValueError, OSError) as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 2
