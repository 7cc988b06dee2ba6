"""Loading and running the example scripts of a folder, as the example tests do."""
import contextlib
import importlib.util
import io
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def load(folder: str, name: str):
    """examples/<folder>/<name>.py as a fresh module (the folder on sys.path for its helpers)."""
    where = ROOT / "examples" / folder
    if str(where) not in sys.path:
        sys.path.insert(0, str(where))
    spec = importlib.util.spec_from_file_location(f"reactor_example_{folder}_{name}", where / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run_all(folder: str, names, out, size: str) -> dict:
    """Each script's ``main(["--out", out, "--size", size, "--repeat", "1"])``, keyed by name, with
    what it printed under ``stdout`` and the directory under ``out``."""
    results = {}
    for name in names:
        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            results[name] = load(folder, name).main(["--out", str(out), "--size", size, "--repeat", "1"])
        results[name]["stdout"] = text.getvalue()
        results[name]["out"] = out
    return results
