"""The local driver: render a path-traced image here, in passes.

Passes are sized by time, not by whole samples per pixel: each aims at
PASS_SECONDS, and when adding one sample to every pixel would take longer, a
pass covers only part of the rows (Renderer.add_rows) -- so the bar moves and
Ctrl-C is answered within about PASS_SECONDS on any image.  A pixel's sums
depend only on its sample indices, so the image does not depend on how the
work was split into passes.  The kernels run in a worker thread while this
thread waits awake to Ctrl-C (kernel/calls.py).
"""
import numba

from .io.preview import NotebookPreview
from .io.tev import TevPreview
from .io.progress import Progress, Spinner, StopOnInterrupt
from .kernel import compile_workers
from .kernel.calls import Abandoned, call_awake

PASS_SECONDS = 0.5      # short passes: a smooth progress bar, a quick Ctrl-C
GROWTH = 4              # a pass does at most this many times the work of the last
#                         (a rate measured on a small pass may flatter the rest)


def render_locally(renderer, spp, time):
    """Passes until spp samples per pixel (or `time` seconds) are rendered, with
    the renderer's options' progress (and threads: Renderer.add_samples).

    Ctrl-C during the compile stops at once (nothing rendered: spp 0; the
    helper processes compiling beside it are stopped too); after,
    it finishes the current pass and returns what was rendered
    (stats.interrupted); a second Ctrl-C raises KeyboardInterrupt at once.
    """
    report = Progress(renderer.options.progress, spp, time)
    preview = _preview(renderer)
    threads = renderer.options.threads or numba.get_num_threads()
    interrupted = False
    try:
        with StopOnInterrupt() as stop, Spinner(renderer.options.progress is True):
            try:
                call_awake(renderer.compile, stop, abandon=True)
            except Abandoned:
                compile_workers.stop_all()      # helper processes too: now
                interrupted = True
            if not interrupted:
                report.started()
                passes, last = 0, 0
                while work := next_pass(renderer, spp, time, last, threads):
                    n, rows = work
                    if rows == renderer.height:
                        call_awake(lambda: renderer.add_samples(n), stop)
                    else:
                        call_awake(lambda: renderer.add_rows(n, rows), stop)
                    passes, last = passes + 1, n * rows
                    report.update(renderer, passes)
                    if preview is not None:
                        preview.update(renderer)
                    if stop.requested:
                        interrupted = spp is None or renderer.spp < spp
                        break
    finally:
        report.close()
    result = renderer.result(spp_requested=spp, interrupted=interrupted,
                             stopped_by="Ctrl-C")
    result.stats.compiled = result.stats.compile_seconds > 0
    if preview is not None:
        preview.show(result)             # the last image stays shown, Ctrl-C or not
        preview.close()
    return result


def _preview(renderer):
    """The live preview the options ask for: a notebook's display, a tev, or None."""
    how = renderer.options.preview
    if isinstance(how, str):
        return TevPreview(how, renderer.name, renderer.width, renderer.height)
    return NotebookPreview() if how else None


def next_pass(r, spp, budget, last, threads=1):
    """(n, rows) of the next pass: n samples per pixel more in `rows` rows
    (r.height: the whole image), or None when finished.

    r: the Renderer (spp, seconds, height, and a pass over part of the rows in
    progress: band, rows_done); last: the row-samples of the previous pass.
    Work is counted in row-samples (one row, one sample per pixel).  The first
    pass is one row per thread (a row of any scene is quick, a whole image of a
    deep one is not); later ones aim at PASS_SECONDS
    at the rate measured so far, growing at most GROWTH times a pass.  A time
    budget stops before a pass that would clearly overrun it, and finishes a
    pass over part of the rows that it started (the image keeps one spp
    everywhere), except on an image so large that one sample per pixel does
    not fit in the budget at all: then it stops with the rows reached.
    """
    h = r.height
    if spp is not None and r.spp >= spp and not r.band:
        return None
    done = r.spp * h + r.rows_done * r.band
    if done == 0:
        return 1, min(h, max(1, threads))
    per_unit = r.seconds / done
    units = max(1.0, PASS_SECONDS / per_unit) if per_unit > 0 else float(h)
    units = min(units, GROWTH * last)
    if budget is not None:
        remaining = budget - r.seconds
        if remaining < 0.5 * per_unit * (r.band or 1):       # not even one row left
            if r.band and r.spp > 0:
                pass            # finish the pass in progress: see above
            else:
                return None
        elif not r.band:
            fits = int(remaining / (per_unit * h))            # whole-image spp that fit
            if fits == 0 and r.spp > 0:
                return None
            units = min(units, max(1.0, remaining / per_unit))
            if fits:
                units = min(units, fits * h)
    if r.band:                          # finish the pass over part of the rows first
        return r.band, min(h - r.rows_done, max(1, int(units // r.band)))
    n = int(units // h)
    if n >= 1:
        return (n if spp is None else min(n, spp - r.spp)), h
    return 1, min(h, max(1, int(units)))
