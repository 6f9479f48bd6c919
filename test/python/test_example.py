"""examples/python/speeds_side_view.py (doc/python.md) as a user runs it:
it draws doc/img/equilibrium_speeds_side.png's picture with matplotlib
(skipped without matplotlib, which tools/setup.sh installs), and the
curves it draws are those of `towstab equilibrium --speed V --json`,
every number equal."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.environ.get("TOWSTAB_SOURCE", os.getcwd())
EXE = os.environ["TOWSTAB_EXE"]
EXAMPLE = os.path.join(ROOT, "examples/python/speeds_side_view.py")
SCENE = os.path.join(ROOT, "examples/kamman_ex1_above.yaml")


def test_example_draws_the_doc_figure(tmp_path):
    image = pytest.importorskip("matplotlib.image")
    p = subprocess.run([sys.executable, EXAMPLE, str(tmp_path)],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "wrote" in p.stdout
    png = image.imread(str(tmp_path / "equilibrium_speeds_side.png"))
    assert png.ndim == 3 and png.shape[0] > 200 and png.shape[1] > 300
    assert np.ptp(png[..., :3]) > 0.5  # drawn, not blank
    curves = json.loads((tmp_path / "speeds_side_view.json").read_text())
    assert [c["speed"] for c in curves] == ["3 knot", "5 knot", "8 knot"]
    for c in curves:
        out = tmp_path / "cli.json"
        subprocess.run([EXE, "equilibrium", SCENE, "--speed", c["speed"],
                        "--quiet", "--json", str(out)], check=True,
                       capture_output=True)
        ref = json.loads(out.read_text())
        assert c["x"] == [n["x"] for n in ref["nodes"]]
        assert c["z"] == [n["z"] for n in ref["nodes"]]
        assert c["trustworthy"] == ref["trustworthy"]
    # Faster, shallower (the picture's order).
    assert curves[0]["z"][-1] > curves[1]["z"][-1] > curves[2]["z"][-1]
