"""A live preview in a Jupyter notebook: one image that updates in place.

render(..., preview=True) shows the result so far -- the tone-mapped image
with its caption (RenderResult._repr_html_): spp, seconds, samples/s and the
standard error -- as one display (IPython's display id), updated after passes
at most every MIN_INTERVAL seconds and once at the end, so that an interrupted
kernel (Ctrl-C: the render returns what it has) leaves its last image shown.
The preview only reads the film: the image is the same bits with or without
it.
"""
import time

from ..errors import SceneError

# Seconds between updates: an update (the result and its PNG) takes 14-17 ms
# at 300x300 and the passes wait for it, so at this interval it costs at most
# about 2.3% (benchmarks/preview.py).
MIN_INTERVAL = 0.75


def in_notebook():
    """Is this code running in a Jupyter kernel (not a terminal IPython)?"""
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


def require():
    """SceneError (one line) unless a notebook can show the preview."""
    if not in_notebook():
        raise SceneError("render: preview: True shows the image as it renders in a Jupyter "
                         "notebook, and this is not one (the progress bar works anywhere)")


class NotebookPreview:
    """The display of one render, updated as it goes."""

    def __init__(self, first=None):
        """Display `first` (a result), or a line saying the render is on."""
        from IPython.display import display
        if first is None:
            self.handle = display({"text/plain": "rendering..."}, raw=True, display_id=True)
        else:
            self.handle = display(first, display_id=True)
        self.last = time.perf_counter() if first is not None else 0.0
        self.updates = 0
        self.seconds = 0.0            # spent making the images shown

    def update(self, renderer, final=False):
        """Show renderer's result so far (not more often than MIN_INTERVAL, but
        always when final)."""
        now = time.perf_counter()
        if not final and now - self.last < MIN_INTERVAL:
            return
        result = renderer.result(denoise=False)
        self.handle.update(result)
        self.last = time.perf_counter()
        self.seconds += self.last - now
        self.updates += 1

    def show(self, result):
        """The final result (denoised too, if asked) in place of the preview."""
        self.handle.update(result)
        self.updates += 1
