"""docs/tour.ipynb, executed headless as a user's Jupyter would run it: the
results show themselves as images, the preview displays once and updates in
place, and every cell runs (its own asserts included)."""
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat", reason="the test extra's nbclient is not installed")
nbclient = pytest.importorskip("nbclient", reason="the test extra's nbclient is not installed")
pytest.importorskip("ipykernel", reason="the test extra's ipykernel is not installed")

TOUR = Path(__file__).resolve().parent.parent / "docs" / "tour.ipynb"


class Counting(nbclient.NotebookClient):
    """A client that counts the display messages each cell sends."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.messages = {}

    def process_message(self, msg, cell, cell_index):
        counts = self.messages.setdefault(cell_index, {})
        counts[msg["msg_type"]] = counts.get(msg["msg_type"], 0) + 1
        return super().process_message(msg, cell, cell_index)


def test_the_tour_runs_and_shows_its_images():
    nb = nbformat.read(TOUR, as_version=4)
    client = Counting(nb, timeout=600, kernel_name="python3",
                      resources={"metadata": {"path": str(TOUR.parent)}})
    client.execute()
    cells = [c for c in nb.cells if c.cell_type == "code"]
    index = {i: c for i, c in enumerate(nb.cells)}

    def outputs(source_start):
        [cell] = [c for c in cells if c.source.startswith(source_start)]
        return cell.outputs, client.messages.get(next(i for i, c in index.items() if c is cell), {})

    shown, _ = outputs("result = rt.render")
    [result] = [o for o in shown if o.output_type == "execute_result"]
    assert "image/png" in result.data and "text/html" in result.data
    assert "120x120, 16 spp" in result.data["text/html"]
    scene, _ = outputs("import numpy")
    assert scene[-1].data["text/plain"].startswith("Scene('cornell_box', 600x600, 8 objects")
    _, live = outputs("live = rt.render")
    assert live.get("display_data") == 1               # one display ...
    assert live.get("update_display_data", 0) >= 2     # ... updated in place
    _, steps = outputs("r = rt.Renderer")
    assert steps.get("display_data") == 1 and steps.get("update_display_data") == 2
    chart, _ = outputs("import matplotlib")
    assert any("image/png" in o.get("data", {}) for o in chart)
