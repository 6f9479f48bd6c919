"""`meson install` installs the package (doc/python.md): into the
Python's site directory, finding the installed library by itself."""

import os
import pathlib
import subprocess
import sys
import tempfile

import pytest

MESON = os.environ.get("TOWSTAB_MESON", "")
BUILD = os.environ["TOWSTAB_BUILD"]
ROOT = os.environ.get("TOWSTAB_SOURCE", os.getcwd())


def test_meson_install_installs_the_package():
    if not MESON:
        pytest.skip("no meson to install with")
    with tempfile.TemporaryDirectory() as d:
        p = subprocess.run([MESON, "install", "-C", BUILD, "--destdir", d,
                            "--no-rebuild", "--quiet"],
                           capture_output=True, text=True)
        assert p.returncode == 0, p.stdout + p.stderr
        inits = list(pathlib.Path(d).glob("**/towstab/__init__.py"))
        assert len(inits) == 1, inits
        pkg = inits[0].parent
        assert (pkg / "_config.py").is_file()
        conf = {}
        exec((pkg / "_config.py").read_text(), conf)
        lib = conf["LIBRARY"]
        assert lib.endswith("/libtowstab.so.0")
        assert os.path.exists(d + lib), "the package names %s" % lib
        # Installed under the prefix (the destdir's copy, as the package
        # would find it there): import it and run an analysis.
        env = dict(os.environ, PYTHONPATH=str(pkg.parent),
                   TOWSTAB_LIBRARY=d + lib)
        code = ("import towstab, sys; s = towstab.Scene.load(sys.argv[1]);"
                "print(towstab.__file__, s.equilibrium().completed)")
        p = subprocess.run([sys.executable, "-c", code,
                            os.path.join(ROOT, "examples/kamman_ex1_above.yaml")],
                           capture_output=True, text=True, env=env,
                           cwd=d)
        assert p.returncode == 0, p.stderr
        assert p.stdout.startswith(str(pkg)) and p.stdout.endswith("True\n")
