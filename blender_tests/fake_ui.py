"""Stand-ins for the window manager, workspace and events, to drive a Tempera
operator's modal path headless (modal timers do not run in background mode):
see modal_run."""
import time
from types import SimpleNamespace


class FakeWindowManager:
    def __init__(self, log):
        self.log, self.timers = log, set()

    def event_timer_add(self, step, window=None):
        timer = object()
        self.timers.add(timer)
        return timer

    def event_timer_remove(self, timer):
        self.timers.remove(timer)  # KeyError if removed twice or unknown

    def modal_handler_add(self, op):
        self.log.append(("modal_handler_add",))

    def progress_begin(self, lo, hi):
        self.log.append(("progress_begin", lo, hi))

    def progress_update(self, value):
        self.log.append(("progress_update", value))

    def progress_end(self):
        self.log.append(("progress_end",))


def modal_run(operator_class, scene, job, events, after_start=None, tick=0.0):
    """Runs `job` through operator_class's modal machinery (what invoke()
    starts in the UI), feeding `events` ((type, value) pairs, e.g.
    ("TIMER", "NOTHING") or ("ESC", "PRESS"), or a function of the operator
    returning an iterable of them) until the operator ends;
    `tick` seconds pass between events (worker threads get time to run).
    Returns (results, log, reports, timers left, operator)."""
    from tempera.blender.job_operator import JobOperator

    log, reports = [], []
    wm = FakeWindowManager(log)
    workspace = SimpleNamespace(status_text_set=lambda text: log.append(("status", text)))
    context = SimpleNamespace(scene=scene, window=object(), window_manager=wm, workspace=workspace,
                              screen=SimpleNamespace(areas=[]))

    class FakeOperator(JobOperator):  # the operator's behaviour on a plain object
        make_job, job_errors = operator_class.make_job, operator_class.job_errors
        job_finished = operator_class.job_finished

        def report(self, kind, message):
            reports.append((set(kind), message))

    op = FakeOperator()
    op._begin(context, job)
    if after_start:
        after_start()
    results = []
    for kind, value in events(op) if callable(events) else events:
        result = op.modal(context, SimpleNamespace(type=kind, value=value))
        results.append(result)
        if result != {"PASS_THROUGH"}:
            break
        time.sleep(tick)
    return results, log, reports, wm.timers, op


def esc_within_next_step(operator_class, scene, job, hold):
    """Runs `job` modally until Esc stops it in the middle of its next step:
    `hold(wrap)` puts, in the job's step, wrap(progress): a progress callback
    that waits for the Esc (at most 60 s) before passing the fraction on, so
    the Esc surely comes within the step however fast the machine. One TIMER
    starts the step in the worker, then Esc. Returns modal_run's tuple."""
    holder = []

    def wrap(progress):
        def wait_for_esc(fraction):
            deadline = time.monotonic() + 60
            while not holder[0]._stop and time.monotonic() < deadline:
                time.sleep(0.01)
            return progress(fraction)
        return wait_for_esc

    hold(wrap)

    def events(op):
        holder.append(op)
        yield ("TIMER", "NOTHING")
        yield ("ESC", "PRESS")

    return modal_run(operator_class, scene, job, events, tick=0.02)
