import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cmake_project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"^project\(tempera VERSION ([0-9.]+)", text, re.MULTILINE)
    assert match, "no project(tempera VERSION x.y.z) in CMakeLists.txt"
    return match.group(1)


@pytest.fixture(scope="session")
def cli_path():
    """The `tempera` CLI binary: $TEMPERA_CLI (set by tools/run_tests.py), else build/bin/tempera."""
    path = Path(os.environ.get("TEMPERA_CLI") or ROOT / "build" / "bin" / "tempera")
    assert path.is_file(), f"tempera CLI not found at {path}; run 'make build'"
    return path


def assert_releases_gil(work):
    """Runs `work` on a thread and checks the main thread kept ticking meanwhile
    (it could not if native code held the GIL for the whole call)."""
    import threading
    import time

    done = threading.Event()

    def run():
        work()
        done.set()

    worker = threading.Thread(target=run)
    ticks = 0
    worker.start()
    start = time.perf_counter()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    elapsed = time.perf_counter() - start
    assert elapsed > 0.05, "too quick to tell"
    assert ticks > 0.2 * elapsed / 0.0015, f"only {ticks} ticks in {elapsed:.2f} s"
