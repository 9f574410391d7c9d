"""The exit statuses of the package's own `tempera` subcommands (rigid,
exemplar), as the native CLI has them (docs/cli.md, "Exit status"): 0 done,
1 a file or program failed, 2 bad usage or a bad value, 130 interrupted."""
import sys


def run_command(prog, run, cancelled="cancelled"):
    """Calls run() and returns its status; the error is printed after `prog`:
    an OSError (a missing or unreadable file, a full disk) gives 1, a
    ValueError 2; Ctrl-C prints `cancelled` and gives 130."""
    try:
        return run()
    except KeyboardInterrupt:
        print(f"{prog}: {cancelled}", file=sys.stderr)
        return 130
    except OSError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1
    except ValueError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 2
