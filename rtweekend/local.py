"""The local driver: render a path-traced image here, in passes.

Each pass adds samples to every pixel (path/renderer.py); between passes the
progress is reported and Ctrl-C is looked at.  Passes aim at PASS_SECONDS each,
so the bar moves and Ctrl-C is answered quickly; the image does not depend on
how the samples were split into passes.
"""
from .io.progress import Progress, StopOnInterrupt

PASS_SECONDS = 0.5      # short passes: a smooth progress bar, a quick Ctrl-C


def render_locally(renderer, spp, time):
    """Passes until spp samples per pixel (or `time` seconds) are rendered, with
    the renderer's options' progress (and threads: Renderer.add_samples).

    Ctrl-C finishes the current pass and returns what was rendered
    (stats.interrupted); a second Ctrl-C raises KeyboardInterrupt.
    """
    report = Progress(renderer.options.progress, spp)
    interrupted = False
    try:
        with StopOnInterrupt() as stop:
            renderer.compile()
            report.started()
            passes = 0
            while n := next_pass(renderer.spp, spp, time, renderer.seconds):
                renderer.add_samples(n)
                passes += 1
                report.update(renderer.spp, passes, renderer.seconds,
                              renderer.width * renderer.height)
                if stop.requested:
                    interrupted = spp is None or renderer.spp < spp
                    break
    finally:
        report.close()
    return renderer.result(spp_requested=spp, interrupted=interrupted, stopped_by="Ctrl-C")


def next_pass(done, spp, budget, elapsed):
    """How many samples per pixel the next pass adds (0: finished).

    The first pass is 1 spp; later passes aim at PASS_SECONDS each, and a time
    budget stops before a pass that would clearly overrun it.
    """
    if done == 0:
        return 1
    per_spp = elapsed / done
    n = max(1, int(PASS_SECONDS / per_spp)) if per_spp > 0 else 1
    if spp is not None:
        return min(n, spp - done)
    remaining = budget - elapsed
    if remaining < 0.5 * per_spp:
        return 0
    return max(1, min(n, int(remaining / per_spp)))
