"""The notebooks of docs/notebooks run: each is executed by nbclient in a fresh ipykernel (an error in
any cell fails the test), in a copy of its folder beside the repository's robots so that the source tree
stays clean, and shows what it is about (the table, the figure, the page). They are stored without
outputs, so that a diff shows only what changed in the code and the text.
"""

import json

import nbformat
import pytest
from nbclient import NotebookClient

from conftest import REPO
from test_jobs import command

NOTEBOOKS = REPO / "docs" / "notebooks"

# what each notebook must show, by output type: a part of its text, or only that one is there
EXPECTED = {
    "table4": [("text/markdown", "| With optimization, paper | [-16.87, 88.06, 11.33] | 1.22 | 0.72 |"),
               ("text/markdown", "| Reduction, ffsr |")],
    "mie_map": [("image/png", None), ("text/plain", "32761 configurations in")],
    "monte_carlo": [("text/markdown", "| optimized |"), ("image/png", None),
                    ("text/plain", "optimized shards joined equal the whole run to the bit: True")],
    "view_3d": [("text/html", "<iframe srcdoc=")],
}


def notebook_names():
    return sorted(p.stem for p in NOTEBOOKS.glob("*.ipynb"))


def test_every_notebook_is_checked():
    assert notebook_names() == sorted(EXPECTED)


@pytest.mark.parametrize("name", notebook_names())
def test_notebook_is_stored_without_outputs(name):
    nb = json.loads((NOTEBOOKS / f"{name}.ipynb").read_text())
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert code and all(c["outputs"] == [] and c["execution_count"] is None for c in code)


def shown(nb):
    """(output type, text) of every output of the executed notebook, streams as text/plain."""
    out = []
    for cell in nb.cells:
        for o in cell.get("outputs", []):
            if o["output_type"] == "stream":
                out.append(("text/plain", o["text"]))
            for kind, value in o.get("data", {}).items():
                out.append((kind, value if isinstance(value, str) else ""))
    return out


@pytest.mark.parametrize("name", notebook_names())
def test_notebook_runs(name, tmp_path, monkeypatch):
    work = tmp_path / "docs" / "notebooks"
    work.mkdir(parents=True)
    (tmp_path / "robots").symlink_to(REPO / "robots")
    source = (NOTEBOOKS / f"{name}.ipynb").read_text()
    if "FFSR_OPTIMIZE" in source:
        monkeypatch.setenv("FFSR_OPTIMIZE", command())  # skips when no command is built
    # the kernel's connection file and IPython's history in the test's folder, not in $HOME
    monkeypatch.setenv("JUPYTER_RUNTIME_DIR", str(tmp_path / "runtime"))
    monkeypatch.setenv("IPYTHONDIR", str(tmp_path / "ipython"))
    nb = nbformat.reads(source, as_version=4)
    resources = {"metadata": {"path": str(work)}}  # the kernel's working folder
    client = NotebookClient(nb, timeout=300, kernel_name="python3", resources=resources)
    client.execute()
    outputs = shown(nb)
    for kind, text in EXPECTED[name]:
        assert any(k == kind and (text is None or text in v) for k, v in outputs), (kind, text, outputs)
