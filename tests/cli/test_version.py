"""The release's identity: one version for both packages and both command lines, a licence in the
repository and in the package metadata, a changelog that names the version."""
import importlib.metadata
import os
import subprocess
import sys

import pytest

import reactor
import routines

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@pytest.mark.parametrize("package", ["reactor", "routines"])
def test_both_command_lines_print_the_version(package):
    run = subprocess.run([sys.executable, "-m", package, "--version"], capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 0 and run.stdout.strip().endswith(reactor.__version__)


def test_one_version_and_a_licence():
    assert routines.__version__ == reactor.__version__
    try:
        meta = importlib.metadata.metadata("reactor-simd")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - run from a tree not installed
        pytest.skip("reactor-simd is not installed")
    assert meta["Version"] == reactor.__version__ and meta["License"] == "MIT"
    with open(os.path.join(ROOT, "LICENSE")) as f:
        assert f.readline().strip() == "MIT License"
    with open(os.path.join(ROOT, "CHANGELOG.md")) as f:
        assert reactor.__version__.split(".dev")[0] in f.read()
