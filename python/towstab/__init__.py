"""towstab: the steady state and linear stability of towed cable systems.

A Python binding of libtowstab (ctypes over the C library's job API,
towstab/job.h; doc/python.md). A scene is loaded from a file, from YAML
text or from a dict; any of its values can be set for a sweep; each
analysis returns a Result whose numbers are exactly those of the command
line's JSON (``towstab KIND SCENE --json``), lists of numbers as numpy
arrays, with the error estimates (``key_values``, ``accuracy``) and the
verdict (``trustworthy``, ``reasons``, ``notes``).

    import towstab
    scene = towstab.Scene.load("examples/kamman_ex3_sphere.yaml")
    eq = scene.equilibrium()
    print(eq.value("top_tension"), eq.trustworthy)
    for v in (1.0, 1.5, 2.0):
        print(v, scene.set("tow.speed", f"{v} m/s").modes(count=4).modes.freq_hz)

SI units throughout, as in the JSON (doc/manual.md, "JSON and CSV").
"""

import ctypes
import json
import math
import os
import signal
import threading
import time

import numpy as np

from towstab import _config

__all__ = ["Scene", "Result", "KeyValue", "Record", "Table", "History",
           "Progress", "TowstabError", "AnalysisError", "Cancelled",
           "library"]

ANALYSES = ("equilibrium", "modes", "response", "simulate", "converge")
# ts_report_result_json's flags (towstab/report_result.h).
REPORT_MATRICES = 1
# TS_ECANCEL (towstab/error.h): a run stopped on request.
ECANCEL = -11
# Wall seconds between the progress reports a long run passes to Python
# (ts_job_progress): the latency of Ctrl-C and of a progress callable.
PROGRESS_INTERVAL = 0.1


class TowstabError(Exception):
    """A refusal or failure of the library: ``code`` (towstab/error.h,
    e.g. -1 TS_EINVAL for bad input) and the message, which names the key
    or option and where it was given."""

    def __init__(self, code, message):
        super().__init__(message)
        self.code = code
        self.message = message


class AnalysisError(TowstabError):
    """An analysis that ran and failed (did not converge, an integrator
    failed): ``result`` holds what was computed (``completed`` false),
    as the command line's JSON of a failed run does."""

    def __init__(self, code, message, result):
        super().__init__(code, message)
        self.result = result


class Cancelled(AnalysisError):
    """A run stopped because its progress callable returned a true value
    (or SIGINT came and the Python handler of SIGINT in place, not the
    default, returned): ``code`` -11 (TS_ECANCEL), the message saying how
    far it got, ``result`` what was computed (``completed`` false)."""


class _Err(ctypes.Structure):
    _fields_ = [("code", ctypes.c_int), ("msg", ctypes.c_char * 1024)]


class _CProgress(ctypes.Structure):
    _fields_ = [("what", ctypes.c_char_p), ("done", ctypes.c_double),
                ("total", ctypes.c_double), ("unit", ctypes.c_char_p)]


_PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(_CProgress),
                                ctypes.c_void_p)


def _find_library():
    path = os.environ.get("TOWSTAB_LIBRARY") or _config.LIBRARY
    return ctypes.CDLL(path)


def _bind(lib):
    P, I, S = ctypes.c_void_p, ctypes.c_int, ctypes.c_char_p
    E = ctypes.POINTER(_Err)
    sig = {
        "ts_units_alloc": (P, [E]),
        "ts_units_free": (None, [P]),
        "ts_scene_load": (P, [S, P, E]),
        "ts_scene_parse": (P, [S, ctypes.c_size_t, S, P, E]),
        "ts_scene_set": (P, [P, I, ctypes.POINTER(S), ctypes.POINTER(S), P,
                             E]),
        "ts_scene_free": (None, [P]),
        "ts_job_alloc": (P, [P, P, S, I, E]),
        "ts_job_free": (None, [P]),
        "ts_job_give": (I, [P, S, S, E]),
        "ts_job_run": (I, [P, E]),
        "ts_job_progress": (I, [P, _PROGRESS_FN, P, ctypes.c_double, E]),
        "ts_job_notes": (S, [P]),
        "ts_job_json": (S, [P, I, E]),
        "ts_job_array": (ctypes.POINTER(ctypes.c_double),
                         [P, S, ctypes.POINTER(I), ctypes.POINTER(I)]),
        "ts_job_matrix": (ctypes.POINTER(ctypes.c_double),
                          [P, S, ctypes.POINTER(I), ctypes.POINTER(I)]),
    }
    for name, (res, args) in sig.items():
        f = getattr(lib, name)
        f.restype = res
        f.argtypes = args
    return lib


library = _bind(_find_library())


class _Units:
    """The unit system (udunits2), read once and shared read-only."""

    def __init__(self):
        err = _Err()
        self.ptr = library.ts_units_alloc(ctypes.byref(err))
        if not self.ptr:
            raise TowstabError(err.code, err.msg.decode())

    def __del__(self):
        if getattr(self, "ptr", None):
            library.ts_units_free(self.ptr)
            self.ptr = None


_units = None


def _get_units():
    global _units
    if _units is None:
        _units = _Units()
    return _units


def _text(value):
    """An option's or a scene value's text: strings as they are (units as
    in a file, "5 knot"), numbers in SI to every digit, booleans as true
    or false, sequences joined by commas."""
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, (list, tuple, np.ndarray)):
        return ",".join(_text(v) for v in value)
    raise TypeError("expected a text, a number, a boolean or a list, got %r"
                    % (value,))


def _yaml_value(value):
    """A value for ts_scene_set: YAML text. Strings are YAML as written
    ("5 knot", "[0, 0, -5 m]"); other values as JSON, which YAML reads."""
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (np.integer, np.floating, np.bool_)):
        value = value.item()
    return json.dumps(value)


class Scene:
    """A scene (doc/scene-format.md) with its system built. Scenes are
    immutable: ``set`` returns a new one."""

    def __init__(self, ptr, units, keep=None):
        self._ptr = ptr
        self._units = units
        self._keep = keep

    @classmethod
    def load(cls, path):
        """Read a scene file (YAML, units as written)."""
        units = _get_units()
        err = _Err()
        ptr = library.ts_scene_load(os.fsencode(path), units.ptr,
                                    ctypes.byref(err))
        if not ptr:
            raise TowstabError(err.code, err.msg.decode())
        return cls(ptr, units)

    @classmethod
    def from_yaml(cls, text, name="scene"):
        """A scene from YAML text; ``name`` is used in messages."""
        units = _get_units()
        data = text.encode()
        err = _Err()
        ptr = library.ts_scene_parse(data, len(data), name.encode(),
                                     units.ptr, ctypes.byref(err))
        if not ptr:
            raise TowstabError(err.code, err.msg.decode())
        return cls(ptr, units)

    @classmethod
    def from_dict(cls, scene, name="scene"):
        """A system built from Python: a dict of the scene format (the
        keys of doc/scene-format.md; quantities as "6 ft" or SI numbers)."""
        return cls.from_yaml(json.dumps(scene, indent=1), name)

    def set(self, key, value=None):
        """A new scene with ``key`` set to ``value`` (or, given a dict,
        every key of it): a key path of the scene format ("tow.speed",
        "cables[0].links", "bodies[fish].mass", "analyses[1].t_end"), a
        value as YAML text with units ("5 knot") or a number in SI; None
        removes the key. The scene is checked as a file is."""
        items = key.items() if isinstance(key, dict) else [(key, value)]
        keys = [k.encode() for k, _ in items]
        vals = [None if v is None else _yaml_value(v).encode()
                for _, v in items]
        n = len(keys)
        karr = (ctypes.c_char_p * n)(*keys)
        varr = (ctypes.c_char_p * n)(*vals)
        err = _Err()
        ptr = library.ts_scene_set(self._ptr, n, karr, varr, self._units.ptr,
                                   ctypes.byref(err))
        if not ptr:
            raise TowstabError(err.code, err.msg.decode())
        return Scene(ptr, self._units)

    def __del__(self):
        if getattr(self, "_ptr", None):
            library.ts_scene_free(self._ptr)
            self._ptr = None

    def run(self, analysis, entry=-1, matrices=False, progress=None,
            **options):
        """Run ``analysis`` ("equilibrium", "modes", "response",
        "simulate", "converge") with the options of the scene's entry
        analyses[entry] (-1: its first entry of that kind, if any) below
        ``options`` (the analysis' options by scene key, ``t_end="12 s"``,
        ``count=6``, as ``towstab ANALYSIS --help`` lists them). A
        repeatable option takes a list (``excite=[...]``). ``matrices``:
        the modes' A and B in the result (as --matrices). A simulation's
        JSON holds the channels of ``outputs`` (``outputs="all"``: the full
        state too); ``history()`` has every node and link whatever it is.
        ``progress``: a callable given a Progress as the run goes (a
        simulation's steps, a response's frequencies, a convergence
        sweep's runs, an equilibrium's Newton Jacobian, the stages and
        ARPACK of modes; its first report of each, then every
        PROGRESS_INTERVAL s); a true return stops the run (Cancelled), an
        exception it raises stops the run and is raised again, with the
        partial result as its ``result``. Ctrl-C (SIGINT) stops a long run
        within PROGRESS_INTERVAL s and raises KeyboardInterrupt, its
        ``result`` the partial result (``completed`` false).
        Raises TowstabError when the
        request is refused (nothing ran), AnalysisError when the analysis
        failed (its partial result attached)."""
        if analysis not in ANALYSES:
            raise TowstabError(-1, "analysis: expected one of %s, got %r"
                               % (", ".join(ANALYSES), analysis))
        err = _Err()
        job = library.ts_job_alloc(self._ptr, self._units.ptr,
                                   analysis.encode(), entry,
                                   ctypes.byref(err))
        if not job:
            raise TowstabError(err.code, err.msg.decode())
        job = _Job(job, self)
        for name, value in options.items():
            texts = value if (name == "excite" and
                              isinstance(value, (list, tuple))) else [value]
            for t in texts:
                if library.ts_job_give(job.ptr, name.encode(),
                                       _text(t).encode(),
                                       ctypes.byref(err)) != 0:
                    raise TowstabError(err.code, err.msg.decode())
        watch = _Watch(progress)
        if library.ts_job_progress(job.ptr, watch.fn, None,
                                   PROGRESS_INTERVAL, ctypes.byref(err)):
            raise TowstabError(err.code, err.msg.decode())
        with watch:
            rc = library.ts_job_run(job.ptr, ctypes.byref(err))
        message = err.msg.decode()
        flags = REPORT_MATRICES if matrices else 0
        text = library.ts_job_json(job.ptr, flags, ctypes.byref(err))
        if text is None:
            watch.raise_pending(None)
            raise TowstabError(rc or err.code, message or err.msg.decode())
        result = Result(json.loads(text), job)
        watch.raise_pending(result)
        if rc == ECANCEL:
            raise Cancelled(rc, message, result)
        if rc != 0:
            raise AnalysisError(rc, message, result)
        return result

    def equilibrium(self, **options):
        """The steady state (doc/equilibrium.md)."""
        return self.run("equilibrium", **options)

    def modes(self, **options):
        """The linear modes about the steady state (doc/linear.md)."""
        return self.run("modes", **options)

    def response(self, **options):
        """A frequency response (doc/linear.md)."""
        return self.run("response", **options)

    def simulate(self, **options):
        """Nonlinear and linear time histories (doc/simulate.md); the
        histories without a copy from ``Result.history``."""
        return self.run("simulate", **options)

    def converge(self, **options):
        """A convergence study (doc/converge.md)."""
        return self.run("converge", **options)


class Progress:
    """How far a long run is, given to a progress callable: ``what`` the
    run ("nonlinear", "linear", "response", "sweep", "sea state",
    "equilibrium", "eigensolve", "rightmost search"), ``done`` of
    ``total`` in ``unit`` ("s" of simulated time, "frequencies", "runs",
    "Jacobian columns", "operator applications": total nan, no end known),
    ``fraction`` done/total;
    ``elapsed`` wall s since the run's first report, ``rate`` units done
    per wall s since then (nan before), ``left`` the wall s estimated to
    the end at that rate (nan when unknown)."""

    def __init__(self, what, done, total, unit, elapsed, rate):
        self.what, self.done, self.total, self.unit = what, done, total, unit
        self.fraction = done / total if total > 0 else math.nan
        self.elapsed = elapsed
        self.rate = rate
        self.left = (total - done) / rate if rate > 0 else math.nan

    def __repr__(self):
        return ("Progress(%s: %.6g of %.6g %s, %.0f%%, %.3g %s per s, "
                "%.3g s left)" % (self.what, self.done, self.total,
                                  self.unit, 100 * self.fraction, self.rate,
                                  self.unit, self.left))


class _Watch:
    """One run's progress callback (ts_job_progress) and its SIGINT
    handler. The handler only notes the signal (it runs when the callback
    runs Python, in the main thread); the callback then asks the run to
    stop. An exception of the caller's callable is kept and raised after
    the run, never through the C code."""

    def __init__(self, callable_):
        self.callable = callable_
        self.fn = _PROGRESS_FN(self._report)
        self.error = None       # what the caller's callable raised
        self.signalled = False  # SIGINT came during the run
        self.previous = None    # the SIGINT handler in place before
        self.run = None         # (what, wall time, done) of the first report

    def _on_sigint(self, signum, frame):
        self.signalled = True

    def __enter__(self):
        # Only a Python handler (the default raises KeyboardInterrupt) is
        # stood in for, only in the main thread (where signals arrive).
        if threading.current_thread() is threading.main_thread():
            h = signal.getsignal(signal.SIGINT)
            if callable(h):
                signal.signal(signal.SIGINT, self._on_sigint)
                self.previous = h
        return self

    def __exit__(self, *exc):
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
        return False

    def _report(self, p, data):
        try:
            if self.signalled or self.error is not None:
                return 1
            if self.callable is None:
                return 0
            c = p.contents
            what = c.what.decode()
            now = time.monotonic()
            if self.run is None or self.run[0] != what or \
                    c.done < self.run[2]:
                self.run = (what, now, c.done)
            elapsed = now - self.run[1]
            rate = ((c.done - self.run[2]) / elapsed if elapsed > 0
                    else math.nan)
            return 1 if self.callable(Progress(what, c.done, c.total,
                                               c.unit.decode(), elapsed,
                                               rate)) else 0
        except BaseException as e:  # KeyboardInterrupt included
            self.error = e
            return 1

    def raise_pending(self, result):
        """After the run: raise what the callable raised, or what SIGINT
        asks (the previous handler's KeyboardInterrupt), with the result
        attached; nothing when neither came."""
        e = self.error
        if e is None and self.signalled:
            h = self.previous
            try:
                if h is signal.default_int_handler:
                    raise KeyboardInterrupt
                h(signal.SIGINT, None)
            except BaseException as caught:
                e = caught
            else:
                if result is None or result.json.get("completed", True):
                    return
                e = Cancelled(ECANCEL, "interrupted (SIGINT): " +
                              str(result.json.get("error")), result)
        if e is None:
            return
        if result is not None and not hasattr(e, "result"):
            try:
                e.result = result
            except AttributeError:
                pass
        raise e


class _Job:
    """The C job: the request and the result, kept alive by the arrays
    that point into it."""

    def __init__(self, ptr, scene):
        self.ptr = ptr
        self.scene = scene  # the job uses the scene: keep it alive
        self.notes = ""

    def __del__(self):
        if getattr(self, "ptr", None):
            library.ts_job_free(self.ptr)
            self.ptr = None

    def array(self, name, column_major=False):
        """A view of the library's array `name` (ts_job_array, or with
        column_major ts_job_matrix); None when the result has none."""
        get = library.ts_job_matrix if column_major else library.ts_job_array
        rows, cols = ctypes.c_int(), ctypes.c_int()
        p = get(self.ptr, name.encode(), ctypes.byref(rows),
                ctypes.byref(cols))
        if not p:
            return None
        n = rows.value * cols.value
        buf = (ctypes.c_double * n).from_address(ctypes.addressof(p.contents))
        buf._job = self  # the array's base holds the job, and so the data
        a = np.frombuffer(buf, dtype=np.float64)
        if column_major:
            a = a.reshape(cols.value, rows.value).T
        else:
            a = a.reshape(rows.value, cols.value)
        a.flags.writeable = False
        return a


def _is_number(x):
    return x is None or (isinstance(x, (int, float)) and
                         not isinstance(x, bool))


def _convert(x):
    """JSON to Python objects: a list of numbers (null: nan) is a numpy
    array, a list of equal lists of numbers a 2-d array, a list of records
    a Table, an object a Record."""
    if isinstance(x, dict):
        return Record(x)
    if isinstance(x, list):
        if x and all(_is_number(v) for v in x):
            if all(isinstance(v, int) for v in x):
                return np.array(x, dtype=np.int64)
            return np.array([np.nan if v is None else v for v in x],
                            dtype=np.float64)
        if x and all(isinstance(v, list) and v and
                     all(_is_number(w) for w in v) and len(v) == len(x[0])
                     for v in x):
            return np.array([[np.nan if w is None else w for w in v]
                             for v in x], dtype=np.float64)
        if x and all(isinstance(v, dict) for v in x):
            return Table(x)
        return [_convert(v) for v in x]
    return np.nan if x is None else x


class Record:
    """A JSON object: its keys as attributes and items; numbers as they
    are (null as nan), lists as numpy arrays or Tables. ``json`` is the
    object as read."""

    def __init__(self, obj):
        self.json = obj
        self._cache = {}

    def __getitem__(self, key):
        if key not in self._cache:
            self._cache[key] = _convert(self.json[key])
        return self._cache[key]

    def __getattr__(self, key):
        if key.startswith("_") or key == "json":
            raise AttributeError(key)
        try:
            return self[key]
        except KeyError:
            raise AttributeError(key) from None

    def __contains__(self, key):
        return key in self.json

    def keys(self):
        return self.json.keys()

    def __repr__(self):
        return "Record(%s)" % ", ".join(self.json.keys())


class Table:
    """A list of JSON records with the same keys: ``table.freq_hz`` is the
    column as a numpy array (null: nan), ``table[i]`` the row as a Record,
    ``table.columns()`` a dict of columns (``pandas.DataFrame(t.columns())``
    makes a frame)."""

    def __init__(self, rows):
        self.rows = rows

    def __len__(self):
        return len(self.rows)

    def __getitem__(self, i):
        if isinstance(i, str):
            return self.column(i)
        return Record(self.rows[i])

    def __iter__(self):
        return (Record(r) for r in self.rows)

    def column(self, key):
        return _convert([r.get(key) for r in self.rows])

    def columns(self):
        keys = []
        for r in self.rows:
            keys += [k for k in r if k not in keys]
        return {k: self.column(k) for k in keys}

    def __getattr__(self, key):
        if key.startswith("_") or key == "rows":
            raise AttributeError(key)
        if not any(key in r for r in self.rows):
            raise AttributeError(key)
        return self.column(key)

    def __repr__(self):
        return "Table(%d rows)" % len(self.rows)


class KeyValue:
    """A key value of a result with its error estimates, in its unit:
    ``discretisation`` (against the continuous cable, doc/accuracy.md) and
    ``solver``; nan where not estimated."""

    def __init__(self, obj):
        e = obj.get("error") or {}
        self.name = obj["name"]
        self.unit = obj["unit"]
        self.value = np.nan if obj["value"] is None else obj["value"]
        self.discretisation = (np.nan if e.get("discretisation") is None
                               else e["discretisation"])
        self.solver = np.nan if e.get("solver") is None else e["solver"]
        self.order = np.nan if obj.get("order") is None else obj["order"]

    def __repr__(self):
        return ("KeyValue(%s = %.10g %s +- %.2g (discretisation) +- %.2g "
                "(solver))" % (self.name, self.value, self.unit,
                               self.discretisation, self.solver))


class History:
    """A simulation's run as arrays that point into the library's result
    (no copy; read-only): ``t`` [samples] s, ``positions`` [samples,
    nodes, 3] m (node 0 the tow point), ``tensions`` [samples, links] N
    (a linear run's from the tension Jacobians), ``tow_force`` [samples,
    3] N (the force on the tow point; nan in a linear run), ``energy``
    [samples, 2] J (nan in a linear run), ``input`` [samples, 18]
    (towstab/job.h)."""

    def __init__(self, job, run):
        t = job.array(run + ".t")
        self.t = t[:, 0]
        p = job.array(run + ".positions")
        self.positions = p.reshape(p.shape[0], p.shape[1] // 3, 3)
        self.tensions = job.array(run + ".tensions")
        self.tow_force = job.array(run + ".tow_force")
        self.energy = job.array(run + ".energy")
        self.input = job.array(run + ".input")


class Result(Record):
    """What an analysis computed: the command line's JSON of it as a
    Record (``result.json`` the dict), with the verdict (``trustworthy``,
    ``completed``, ``reasons``, ``notes``, ``error``), the key values with
    their error estimates (``key_values``, ``value(name)``, ``errors(name)``)
    and the discretisation estimate (``accuracy``). ``request_notes``: the
    scene values that yielded to their defaults because the options given
    contradict them (the command line's "note:" lines), one a line."""

    def __init__(self, obj, job):
        super().__init__(obj)
        self._job = job
        self.kind = obj.get("type")
        self.request_notes = library.ts_job_notes(job.ptr).decode()

    @property
    def key_values(self):
        return [KeyValue(v) for v in self.json.get("key_values", [])]

    def _key(self, name):
        for v in self.json.get("key_values", []):
            if v["name"] == name:
                return KeyValue(v)
        raise KeyError("%s: the result has no key value of this name "
                       "(it has %s)" % (name, ", ".join(
                           v["name"] for v in self.json.get("key_values",
                                                            []))))

    def value(self, name):
        """The key value ``name`` ("top_tension", "mode1.freq_hz")."""
        return self._key(name).value

    def errors(self, name):
        """The error estimates of key value ``name``: (discretisation,
        solver), nan when not estimated."""
        k = self._key(name)
        return k.discretisation, k.solver

    def matrix(self, name):
        """A matrix of the linear model or the modes, a view of the
        library's (read-only, no copy, column-major): "A" [n, n] and "B"
        [n, inputs] of the dense linear model, "vectors_re" and
        "vectors_im" [n, modes] (column m the right eigenvector of mode m,
        the order of ``modes``); None when the result has none."""
        return self._job.array(name, column_major=True)

    def eigenvectors(self):
        """The right eigenvectors as one complex array [n, modes] (a copy
        made of ``matrix("vectors_re")`` and ``"vectors_im"``); None
        without them."""
        re, im = self.matrix("vectors_re"), self.matrix("vectors_im")
        return None if re is None or im is None else re + 1j * im

    def history(self, run="nonlinear"):
        """A simulation's ``nonlinear`` or ``linear`` run as arrays, not
        copied; None when the result has no such run."""
        if self._job.array(run + ".t") is None:
            return None
        return History(self._job, run)

    def __repr__(self):
        return "Result(%s, trustworthy=%s, completed=%s)" % (
            self.kind, self.json.get("trustworthy"),
            self.json.get("completed"))
