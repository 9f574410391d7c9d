"""The long-running operators' shared machinery: a job run step by step.

A job is any object with

    total, index, finished      steps in all, steps done, index >= total
    step(progress)              does the next step; progress(fraction) follows it
                                and returning False from it asks the step to stop
    threaded()                  True if the next step may run off the main thread
                                (it touches no bpy data: the native solver)
    status_text()               "Tempera: ... i/N, ETA ..." for the status bar
    summary()                   one line for the final report
    failure(exc)                the report line of a failed step

In background mode (blender -b, no timers) execute() runs every step in turn.
In the UI, invoke() makes the operator modal: a window-manager timer runs one
step per tick with a progress cursor and the status text; steps that allow it
run in a worker thread so the interface stays responsive and Esc stops them
mid-step (the native solver checks its progress callback). Esc between steps
stops before the next. Finished steps are never undone.
"""
import concurrent.futures
import traceback

import bpy

from .. import Cancelled

TIMER_STEP = 0.1  # seconds between timer ticks: redraws and Esc are seen this often

# The Tempera job running in this Blender, if any (its operator's label):
# one at a time, whichever operator started it (see JobOperator.poll).
_RUNNING = {"label": None}


def running_job():
    """The label of the Tempera job running now ("Render Guides", "Stylize"), or None."""
    return _RUNNING["label"]


def _set_running(operator, running):
    _RUNNING["label"] = (getattr(operator, "bl_label", None) or type(operator).__name__) if running else None


class JobOperator:
    """Mix-in for bpy.types.Operator subclasses; they define make_job(context)
    returning the job or raising one of job_errors (reported, nothing done)."""

    job_errors = (ValueError,)

    @classmethod
    def poll(cls, context):
        """Disabled while any Tempera job runs in this Blender (rendering
        guides and stylizing share the scene's renders and output folders)."""
        label = running_job()
        if label is not None:
            cls.poll_message_set(f"Tempera is busy ({label} is running; Esc stops it)")
            return False
        return context.scene is not None and hasattr(context.scene, "tempera")

    def make_job(self, context):
        raise NotImplementedError

    def confirmation(self, job):
        """A question to ask before a long run in the UI, or None (no question)."""
        return None

    def job_finished(self, context, job):
        """Called once after the last step (not when stopped or failed)."""

    # -- shared

    def _start(self, context):
        try:
            return self.make_job(context)
        except self.job_errors as exc:
            self.report({"ERROR"}, str(exc))
            return None

    def _run_step(self, job, progress=None):
        """One step; True if it went well, else the error is reported."""
        try:
            job.step(progress)
            return True
        except Cancelled:
            raise
        except self.job_errors as exc:
            message = job.failure(exc)
        except Exception as exc:  # e.g. disk full: a message for the artist, the details on the console
            traceback.print_exc()
            message = job.failure(f"{type(exc).__name__}: {exc}")
        self.report({"ERROR"}, message)
        return False

    def _complete(self, context, job):
        try:
            self.job_finished(context, job)
        except self.job_errors as exc:
            self.report({"WARNING"}, str(exc))
        self.report({"INFO"}, job.summary())

    # -- background / scripts: every step now

    def execute(self, context):
        if getattr(self, "question", "") and not bpy.app.background and context.window is not None:
            return self._execute_confirmed(context)
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        wm = context.window_manager
        _set_running(self, True)
        wm.progress_begin(0, job.total)
        try:
            while not job.finished:
                if bpy.app.background:
                    print(job.status_text().replace(" (Esc to stop)", ""), flush=True)
                done = job.index
                if not self._run_step(job, lambda f: wm.progress_update(done + f)):
                    return {"CANCELLED"}
                wm.progress_update(job.index)
        finally:
            wm.progress_end()
            _set_running(self, False)
        self._complete(context, job)
        return {"FINISHED"}

    # -- UI: one step per timer tick

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        question = self.confirmation(job)
        if question and hasattr(self, "question"):
            # A dialog first; its OK calls execute(), which then goes modal too.
            self.question = question
            return context.window_manager.invoke_props_dialog(self, width=460)
        self._begin(context, job)
        return {"RUNNING_MODAL"}

    def draw(self, _context):
        """The confirmation dialog's text (one label per line)."""
        for line in getattr(self, "question", "").split("\n"):
            self.layout.label(text=line)

    def _execute_confirmed(self, context):
        """execute() after the confirmation dialog's OK, in the UI: modal."""
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        self._begin(context, job)
        return {"RUNNING_MODAL"}

    def _begin(self, context, job):
        self._over = False
        self._job_state = job
        self._worker, self._future, self._fraction, self._stop = None, None, 0.0, False
        wm = context.window_manager
        _set_running(self, True)
        self._timer = wm.event_timer_add(TIMER_STEP, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, job.total)
        self._show(context, job)

    def modal(self, context, event):
        if getattr(self, "_over", False):
            # A copy of this handler (Blender copies a window's handlers into
            # a window opened meanwhile) must not step a finished job again.
            return {"FINISHED"}
        job = self._job_state
        if event.type == "ESC" and event.value == "PRESS":
            self._stop = True
            self._wait_for_worker()
            self._finish(context)
            self.report({"WARNING"}, f"Stopped. {job.summary()}")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        wm = context.window_manager
        if self._future is not None:  # a threaded step is running
            if not self._future.done():
                wm.progress_update(job.index + self._fraction)
                return {"PASS_THROUGH"}
            ok = self._collect()
        elif job.threaded():
            self._fraction = 0.0
            self._future = self._executor().submit(job.step, self._progress)
            return {"PASS_THROUGH"}
        else:
            # The step blocks the main thread (it renders with bpy); a fresh
            # timer after it lets the window redraw and Esc be seen first.
            wm.event_timer_remove(self._timer)
            self._timer = None
            done = job.index
            ok = self._run_step(job, lambda f: wm.progress_update(done + f))
            self._timer = wm.event_timer_add(TIMER_STEP, window=context.window)
        if not ok:
            self._finish(context)
            return {"CANCELLED"}
        if job.finished:
            self._finish(context)
            self._complete(context, job)
            return {"FINISHED"}
        wm.progress_update(job.index)
        self._show(context, job)
        return {"PASS_THROUGH"}

    def cancel(self, context):
        """Blender ends the operator (a file is loaded, the window closes)."""
        self._stop = True
        self._wait_for_worker()
        self._finish(context)

    # -- worker thread

    def _executor(self):
        if self._worker is None:
            self._worker = concurrent.futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="tempera")
        return self._worker

    def _progress(self, fraction):
        """Called from the worker: remember the fraction; False stops the step."""
        self._fraction = fraction
        return not self._stop

    def _collect(self):
        """The finished threaded step's outcome, reported like a main-thread step."""
        future, self._future = self._future, None
        job = self._job_state
        return self._run_step(_Finished(job, future))

    def _wait_for_worker(self):
        if getattr(self, "_future", None) is not None:
            concurrent.futures.wait([self._future])
            self._future = None

    def _show(self, context, job):
        if context.workspace is not None:
            context.workspace.status_text_set(job.status_text())
        _redraw_properties(context)

    def _finish(self, context):
        self._over = True
        wm = context.window_manager
        if getattr(self, "_timer", None) is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        if getattr(self, "_worker", None) is not None:
            self._worker.shutdown(wait=True)
            self._worker = None
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        _redraw_properties(context)
        _set_running(self, False)


class _Finished:
    """A job whose step() re-raises what a worker's step raised (so that the
    error is reported by the same code as a main-thread step's)."""

    def __init__(self, job, future):
        self._job, self._future = job, future

    def step(self, _progress=None):
        self._future.result()

    def failure(self, exc):
        return self._job.failure(exc)


def _redraw_properties(context):
    """The panel's status lines follow the frames as they are written."""
    screen = context.screen
    for area in screen.areas if screen else ():
        if area.type == "PROPERTIES":
            area.tag_redraw()
