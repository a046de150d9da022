"""The package's metadata builds as pip builds it, without setuptools' deprecation warnings."""

import shutil
import subprocess
import sys
from email.parser import Parser
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BUILD = """
import sys
from setuptools import build_meta
print(build_meta.prepare_metadata_for_build_editable(sys.argv[1]))
"""


def test_the_metadata_builds_without_deprecation_warnings(tmp_path):
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, tmp_path / name)
    (tmp_path / "gymfg_il").mkdir()
    (tmp_path / "gymfg_il" / "__init__.py").touch()
    out = tmp_path / "meta"
    out.mkdir()
    done = subprocess.run(
        [sys.executable, "-c", BUILD, str(out)], cwd=tmp_path, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Deprecat" not in done.stderr + done.stdout  # project.license as a table was
    info = done.stdout.strip().splitlines()[-1]
    metadata = Parser().parsestr((out / info / "METADATA").read_text())
    assert metadata["License-Expression"] == "MIT"
