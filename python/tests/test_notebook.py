"""examples/tessera.ipynb runs headless (nbclient) and its output cells hold
the rendered images as PNG."""
import base64
import os
import struct

import pytest

from conftest import BUILD, ROOT

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")


def test_the_example_notebook_executes_and_shows_images():
    path = os.path.join(ROOT, "examples", "tessera.ipynb")
    nb = nbformat.read(path, as_version=4)
    os.environ["PYTHONPATH"] = os.path.join(ROOT, "python") + os.pathsep + os.environ.get(
        "PYTHONPATH", "")
    os.environ["TESSERA_BUILD_DIR"] = BUILD
    client = nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                                     resources={"metadata": {"path": ROOT}})
    # Debian's nbclient (0.7) reads the widget messages of ipywidgets >= 7;
    # Debian's ipywidgets is 6.0: its widget state is not recorded here (the
    # widget's view is still a cell output).
    client.comm_open_handlers = {}
    client.execute()
    pngs, widgets = [], 0
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            assert out.get("output_type") != "error", out
            data = out.get("data", {})
            if "image/png" in data:
                pngs.append(base64.b64decode(data["image/png"]))
            if "application/vnd.jupyter.widget-view+json" in data:
                widgets += 1
    sizes = [struct.unpack(">II", p[16:24]) for p in pngs]
    print(f"notebook: {len(pngs)} PNG outputs {sizes}, {widgets} widget views")
    assert len(pngs) >= 4
    assert all(p.startswith(b"\x89PNG") and len(p) > 2000 for p in pngs)
    assert (512, 512) in sizes
    assert widgets >= 1
