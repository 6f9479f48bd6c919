"""The Python package (doc/python.md) against the command line.

Run by test/python/run.sh under `meson test` (suite python) with
TOWSTAB_EXE (the built towstab), TOWSTAB_LIBRARY (the built library) and
PYTHONPATH (the package in the build tree). Every analysis' result is the
command line's JSON exactly: every number equal to the last digit (the
same pipeline, the same serialiser; run times aside), and the numpy
arrays and key values made of it hold those numbers; a scene value set
from Python gives what the command line's option gives; histories read
without a copy equal the JSON's samples; bad input raises with the
key's or option's name; a failed run carries its partial result.
"""

import gc
import json
import math
import os
import subprocess

import numpy as np
import pytest

import towstab

ROOT = os.environ.get("TOWSTAB_SOURCE", os.getcwd())
EXE = os.environ["TOWSTAB_EXE"]
ALL = os.path.join(ROOT, "test/cli/report/all_kinds.yaml")
FAILS = os.path.join(ROOT, "test/cli/report/fails.yaml")
EX1 = os.path.join(ROOT, "examples/kamman_ex1_above.yaml")
# Keys that hold run times, which differ from run to run.
TIMES = ("wall_s", "simulated_per_wall", "prediction", "work_precision")


def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items()
                if not any(k.startswith(t) for t in TIMES)}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x


def cli(tmp_path, *args):
    out = tmp_path / "cli.json"
    p = subprocess.run([EXE, *args, "--quiet", "--json", str(out)],
                       capture_output=True, text=True)
    assert p.returncode in (0, 1), p.stderr
    return json.loads(out.read_text())


def same(py, ref, where="result"):
    """py (the package's objects) holds exactly the numbers of ref (the
    command line's JSON): nan for null, arrays element by element."""
    if isinstance(ref, dict):
        for k, v in ref.items():
            if any(k.startswith(t) for t in TIMES):
                continue
            same(py[k], v, where + "." + k)
    elif isinstance(ref, list):
        assert len(py) == len(ref), where
        for i, v in enumerate(ref):
            same(py[i], v, "%s[%d]" % (where, i))
    elif ref is None:
        assert isinstance(py, float) and math.isnan(py), where
    elif isinstance(ref, (int, float)) and not isinstance(ref, bool):
        assert py == ref and type(float(py)) is float, \
            "%s: %r != %r" % (where, py, ref)
    else:
        assert py == ref, where


@pytest.fixture(scope="module")
def scene():
    return towstab.Scene.load(ALL)


CASES = [
    ("equilibrium", {}, []),
    ("modes", {"count": 6}, ["--count", "6"]),
    ("response", {"output": "sphere.z", "points": 40},
     ["--output", "sphere.z", "--points", "40"]),
    ("simulate", {"excite": "tow.heave:amplitude=0.5in,frequency=0.5Hz",
                  "t_end": "8 s", "transient": "4 s", "compare": True,
                  "output": "sphere.z"},
     ["--excite", "tow.heave:amplitude=0.5in,frequency=0.5Hz",
      "--t-end", "8 s", "--transient", "4 s", "--compare",
      "--output", "sphere.z"]),
    ("converge", {"links": "5,10,20"}, ["--links", "5,10,20"]),
]


@pytest.mark.parametrize("kind,options,args", CASES,
                         ids=[c[0] for c in CASES])
def test_equals_cli_json(scene, tmp_path, kind, options, args):
    # The scene's own entry is not taken (entry of another kind would be
    # refused): the options given are the command line's.
    r = scene.run(kind, **options)
    ref = cli(tmp_path, kind, ALL, *args)
    assert strip(r.json) == strip(ref)
    same(r, ref)
    assert r.kind == kind
    assert r.completed is True and isinstance(r.trustworthy, bool)
    assert r.trustworthy == ref["trustworthy"]
    assert r.reasons == ref["reasons"] and r.notes == ref["notes"]
    for kv, rv in zip(r.key_values, ref["key_values"]):
        assert kv.name == rv["name"] and kv.value == rv["value"]
        d = rv["error"]["discretisation"]
        assert kv.discretisation == d or (d is None and
                                          math.isnan(kv.discretisation))
        assert r.value(kv.name) == rv["value"]
    if kind != "converge":
        assert r.accuracy.accuracy == ref["accuracy"]["accuracy"]
        same(r.accuracy.met, ref["accuracy"]["met"], "accuracy.met")


def test_arrays_are_numpy(scene):
    eq = scene.equilibrium()
    assert isinstance(eq.nodes.z, np.ndarray) and eq.nodes.z.dtype == float
    assert isinstance(eq.tow_force, np.ndarray) and eq.tow_force.shape == (3,)
    m = scene.modes(count=6)
    cols = m.modes.columns()
    assert set(("freq_hz", "damping_ratio", "re", "im")) <= set(cols)
    assert np.all(np.isfinite(cols["re"]))
    assert m.accuracy.levels.dtype == np.int64


def test_history_without_copy_equals_json(scene, tmp_path):
    r = scene.simulate(excite="tow.heave:amplitude=0.5in,frequency=0.5Hz",
                       t_end="4 s", compare=True, outputs="all")
    h = r.history()
    lin = r.history("linear")
    assert h is not None and lin is not None
    # Views into the library's result, read-only.
    for a in (h.t, h.positions, h.tensions, lin.positions):
        assert not a.flags.owndata and not a.flags.writeable
    ref = r.json["nonlinear"]["history"]
    assert np.array_equal(h.t, np.array(ref["t"]))
    n = len(ref["nodes"])
    assert h.positions.shape == (len(ref["t"]), n, 3)
    for i, node in enumerate(ref["nodes"]):
        for c, axis in enumerate("xyz"):
            assert np.array_equal(h.positions[:, i, c], np.array(node[axis]))
    assert h.tensions.shape == (len(ref["t"]), 10)
    for k, link in enumerate(ref["tensions"]):
        assert np.array_equal(h.tensions[:, k], np.array(link["tension"]))
    for c, axis in enumerate("xyz"):
        assert np.array_equal(h.tow_force[:, c],
                              np.array(ref["tow_force"][axis]))
    assert np.array_equal(h.energy[:, 0], np.array(ref["energy"]["kinetic"]))
    # The linear run's tensions come from the tension Jacobians; within
    # 1 % of the nonlinear run's under this 0.5 in heave.
    assert np.all(np.abs(lin.tensions - h.tensions) < 0.01 * h.tensions)
    assert np.all(np.isnan(lin.tow_force))
    # The arrays keep the result alive.
    t0 = h.positions[-1].copy()
    del r, h
    gc.collect()
    junk = [scene.equilibrium() for _ in range(3)]
    assert np.array_equal(lin.positions[0, 0], lin.positions[0, 0])
    assert len(junk) == 3 and t0.shape == (n, 3)
    assert towstab.Scene.load(ALL).equilibrium().history() is None


@pytest.mark.parametrize("key,value,args", [
    ("tow.speed", "3 knot", ["--speed", "3 knot"]),
    ("tow.speed", 1.5, ["--speed", "1.5"]),
    ("cables[0].links", 20, ["--links", "20"]),
])
def test_set_equals_option(tmp_path, key, value, args):
    s = towstab.Scene.load(EX1).set(key, value)
    r = s.equilibrium()
    ref = cli(tmp_path, "equilibrium", EX1, *args)
    assert strip(r.json) == strip(ref)


def test_sweep(tmp_path):
    base = towstab.Scene.load(EX1)
    speeds = ["3 knot", "5 knot", "8 knot"]
    depths = [base.set("tow.speed", v).equilibrium().bodies.z[0]
              for v in speeds]
    # Faster tows ride higher (doc/equilibrium.md): the depth falls.
    assert depths[0] > depths[1] > depths[2]
    ref = cli(tmp_path, "equilibrium", EX1, "--speed", "8 knot")
    assert depths[2] == ref["bodies"][0]["z"]
    # The base scene is unchanged.
    assert base.equilibrium().json["speed"] != ref["speed"]
    # Several keys at once: as one after the other.
    both = base.set({"tow.speed": "5 knot", "cables[0].links": 12})
    one = base.set("tow.speed", "5 knot").set("cables[0].links", 12)
    assert strip(both.equilibrium().json) == strip(one.equilibrium().json)
    assert strip(both.equilibrium().json) != strip(
        base.set("tow.speed", "5 knot").equilibrium().json)


def test_scene_from_dict():
    d = {"name": "from python",
         "tow": {"speed": "1.5 m/s"},
         "cables": [{"name": "c", "from": "tow", "to": "ball",
                     "length": 20, "diameter": 0.01,
                     "mass_per_length": 0.2, "links": 8}],
         "bodies": [{"name": "ball", "type": "sphere", "diameter": 0.3,
                     "mass": 30}]}
    eq = towstab.Scene.from_dict(d).equilibrium()
    assert eq.completed and eq.json["converged"]
    assert len(eq.links) == 8 and eq.bodies.z[0] > 0
    # The same scene as YAML text gives the same numbers.
    y = towstab.Scene.from_yaml(json.dumps(d)).equilibrium()
    assert strip(y.json) == strip(eq.json)


def test_bad_input_names_the_key():
    s = towstab.Scene.load(ALL)
    with pytest.raises(towstab.TowstabError) as e:
        s.set("tow.sped", 1)
    assert "tow.sped" in str(e.value) and e.value.code == -4
    with pytest.raises(towstab.TowstabError) as e:
        s.modes(cout=3)
    assert "cout" in str(e.value) and e.value.code == -1
    with pytest.raises(towstab.TowstabError) as e:
        s.simulate(t_end=-1)
    assert str(e.value).startswith("t_end: ") and e.value.code == -1
    with pytest.raises(towstab.TowstabError) as e:
        s.run("bode")
    assert "bode" in str(e.value)
    with pytest.raises(towstab.TowstabError) as e:
        towstab.Scene.load(os.path.join(ROOT, "no/such.yaml"))
    assert "no/such.yaml" in str(e.value) and e.value.code == -3
    with pytest.raises(towstab.TowstabError):
        towstab.Scene.from_yaml("tow: [")


def test_failed_run_carries_its_result(tmp_path):
    s = towstab.Scene.load(FAILS)
    with pytest.raises(towstab.AnalysisError) as e:
        s.run("simulate", entry=1)
    r = e.value.result
    assert r.completed is False and r.trustworthy is False
    assert "h_min" in e.value.message and r["error"] == e.value.message
    assert r.error == e.value.message
    assert r.history() is not None and len(r.history().t) > 0


def test_scene_value_yields_as_on_the_command_line(scene, tmp_path):
    # The scene's simulate entry has transient 4 s; t_end 4 s given over
    # it: the transient yields to its default, with a note, as in
    # `towstab simulate SCENE --t-end 4`.
    r = scene.simulate(t_end="4 s")
    assert "transient" in r.request_notes
    ref = cli(tmp_path, "simulate", ALL, "--t-end", "4 s")
    assert strip(r.json) == strip(ref)
    assert scene.simulate().request_notes == ""


def test_matrices_without_copy(scene, tmp_path):
    m = scene.modes(count=6, matrices=True)
    ref = cli(tmp_path, "modes", ALL, "--count", "6", "--matrices")
    assert strip(m.json) == strip(ref)
    A, B = m.matrix("A"), m.matrix("B")
    # Views of the library's column-major arrays, read-only.
    for a in (A, B, m.matrix("vectors_re")):
        assert a.flags.f_contiguous and not a.flags.owndata
        assert not a.flags.writeable
    # The JSON's A and B (rows) to the last digit.
    assert np.array_equal(A, np.array(ref["linearization"]["A"]))
    assert np.array_equal(B, np.array(ref["linearization"]["B"]))
    # Each eigenvector with its eigenvalue: A v = lambda v, to 1e-9 of
    # |lambda| (LAPACK's residuals are near rounding, ~1e-12; the error
    # bounds, ~1e-8, are larger).
    V = m.eigenvectors()
    lam = m.modes.re + 1j * m.modes.im
    assert V.shape == (A.shape[0], len(lam))
    for k in range(len(lam)):
        v = V[:, k]
        assert abs(np.linalg.norm(v) - 1) < 1e-12
        assert np.linalg.norm(A @ v - lam[k] * v) <= 1e-9 * abs(lam[k])
    assert scene.equilibrium().matrix("A") is None
