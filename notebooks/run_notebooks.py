"""Execute every notebook in this folder headlessly; fail on the first error.

The notebooks are committed without outputs (this script refuses any that has some) and are
executed in memory, so the working tree stays clean. They expect the release binaries:
run `cargo build --release` first (CI does).
"""
import pathlib
import sys

import nbformat
from nbclient import NotebookClient

here = pathlib.Path(__file__).resolve().parent
notebooks = sorted(here.glob("*.ipynb"))
if not notebooks:
    sys.exit("no notebooks found")
for path in notebooks:
    nb = nbformat.read(path, as_version=4)
    stale = [c for c in nb.cells if c.cell_type == "code" and (c.get("outputs") or c.get("execution_count"))]
    if stale:
        sys.exit(f"{path.name}: committed with outputs; strip them (e.g. jupyter nbconvert --clear-output)")
    print(f"executing {path.name} …", flush=True)
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(here)}}).execute()
    print(f"{path.name}: ok", flush=True)
print(f"{len(notebooks)} passed, 0 failed")
