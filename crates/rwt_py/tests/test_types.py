"""The package's types: `mypy --strict` passes on the package's sources (with the stubs of
its native module, as the wheel ships them) and on a user's script that passes numpy
scalars, arrays and generators (`typed_use.py`)."""

import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mypy")


def test_mypy_strict_passes_on_the_package_and_a_users_script():
    package = Path(__file__).resolve().parents[1] / "python" / "rwt_noise"
    script = Path(__file__).with_name("typed_use.py")
    run = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--no-incremental",
                          str(package), str(script)], capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
