"""Progress reports and stopping of long runs from Python (doc/python.md,
"Progress and Ctrl-C").

A progress callable sees the runs go (simulated time rising to t_end, a
rate and the time left); returning a true value stops the run (Cancelled,
the partial result attached, completed false); an exception it raises
stops the run and comes out of the call with the partial result; SIGINT
sent to the process from a timer during a long simulation stops it within
seconds and raises KeyboardInterrupt with the partial result; the SIGINT
handler in place before is back after every call.
"""

import math
import os
import signal
import threading
import time

import pytest

import towstab

ROOT = os.environ.get("TOWSTAB_SOURCE", os.getcwd())
EX1 = os.path.join(ROOT, "examples/kamman_ex1_above.yaml")
ALL = os.path.join(ROOT, "test/cli/report/all_kinds.yaml")


@pytest.fixture(scope="module")
def ex1():
    return towstab.Scene.load(EX1)


@pytest.fixture
def sigint_default():
    """SIGINT raising KeyboardInterrupt, as in an interactive Python (a
    test runner started in the background may have it ignored)."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


def test_every_report_in_order(ex1, monkeypatch):
    monkeypatch.setattr(towstab, "PROGRESS_INTERVAL", 0.0)
    reports = []
    r = ex1.simulate(t_end="5 s", discretisation_error=False,
                     progress=reports.append)
    assert r.completed is True
    # The initial equilibrium's stage first, then the simulation's steps.
    assert reports[0].what == "equilibrium"
    seen = [p for p in reports if p.what != "equilibrium"]
    assert reports[-len(seen):] == seen
    assert len(seen) > 10
    assert all(p.what == "nonlinear" and p.unit == "s" and p.total == 5.0
               for p in seen)
    done = [p.done for p in seen]
    assert done == sorted(done) and done[-1] == pytest.approx(5.0, 1e-12)
    last = seen[-1]
    assert last.fraction == pytest.approx(1.0, 1e-12)
    # Rate and time left from the wall clock: positive, and no time left
    # at the end.
    assert last.elapsed > 0 and last.rate > 0 and last.left == 0.0
    mid = seen[len(seen) // 2]
    assert mid.left == pytest.approx((5.0 - mid.done) / mid.rate)


def test_throttled_to_the_interval(ex1):
    seen = []
    t0 = time.monotonic()
    ex1.simulate(t_end="5 s", discretisation_error=False,
                 progress=seen.append)
    wall = time.monotonic() - t0
    # The first report, then at most one per PROGRESS_INTERVAL s.
    assert 1 <= len(seen) <= 1 + wall / towstab.PROGRESS_INTERVAL + 1
    assert seen[0].done < 0.1


def test_return_true_stops(ex1):
    seen = []

    def stop_at_first(p):
        if p.what == "equilibrium":
            return False
        seen.append(p)
        return True

    with pytest.raises(towstab.Cancelled) as e:
        ex1.simulate(t_end="100 s", progress=stop_at_first)
    assert len(seen) == 1
    assert isinstance(e.value, towstab.AnalysisError)
    assert e.value.code == towstab.ECANCEL
    assert "stopped on request" in e.value.message
    r = e.value.result
    assert r.completed is False and r.trustworthy is False
    h = r.history()
    assert h is not None and 0 < len(h.t) and h.t[-1] <= seen[0].done < 100


def test_exception_stops_and_is_raised(ex1):
    class Enough(Exception):
        pass

    def fail(p):
        if p.what != "equilibrium":
            raise Enough("seen %g s" % p.done)

    with pytest.raises(Enough) as e:
        ex1.simulate(t_end="100 s", progress=fail)
    r = e.value.result
    assert r.completed is False and r.history().t[-1] < 100


def test_keyboard_interrupt_in_callable(ex1):
    def interrupt(p):
        if p.what != "equilibrium":
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as e:
        ex1.simulate(t_end="100 s", progress=interrupt)
    assert e.value.result.completed is False


def test_stops_in_the_discretisation_estimate(ex1):
    # The estimate's runs at fewer links start again from t = 0: their
    # first reports pass whatever the interval, and stopping there leaves
    # the estimate undone, saying why.
    seen = []

    def stop_at_restart(p):
        seen.append(p.done)
        # Within a run the time only rises.
        return len(seen) > 1 and p.done <= seen[-2]

    with pytest.raises(towstab.Cancelled) as e:
        ex1.simulate(t_end="20 s", discretisation_error=True,
                     progress=stop_at_restart)
    a = e.value.result.accuracy
    assert seen[-1] < 1
    assert a.estimated is False and "stopped" in a.not_estimated


def test_response_stops_between_frequencies(monkeypatch):
    monkeypatch.setattr(towstab, "PROGRESS_INTERVAL", 0.0)
    s = towstab.Scene.load(ALL)
    seen = []

    def after_three(p):
        if p.what == "equilibrium":
            return False
        seen.append(p)
        return p.done >= 3

    with pytest.raises(towstab.Cancelled) as e:
        s.response(output="sphere.z", points=40, progress=after_three)
    assert [p.done for p in seen] == [1.0, 2.0, 3.0]
    assert seen[-1].what == "response" and seen[-1].total == 40.0
    assert e.value.result.completed is False
    assert "after 3 of 40 frequencies" in e.value.message


def test_converge_stops_between_runs(monkeypatch):
    monkeypatch.setattr(towstab, "PROGRESS_INTERVAL", 0.0)
    s = towstab.Scene.load(ALL)
    seen = []

    def after_two_runs(p):
        seen.append((p.what, p.done, p.total, p.unit))
        return p.what == "sweep" and p.done >= 2

    with pytest.raises(towstab.Cancelled) as e:
        s.converge(links="5,10,20,40", progress=after_two_runs)
    sweeps = [x for x in seen if x[0] == "sweep"]
    assert sweeps[0] == ("sweep", 0.0, 4.0, "runs")
    assert sweeps[-1][1] == 2.0
    r = e.value.result
    assert r.completed is False
    # The runs finished before the stop are kept.
    assert len(r.rows) == 2 and list(r.rows.setting) == [5, 10]
    assert "after 2 of 4 runs" in e.value.message


def test_sigint_stops_a_long_simulation(ex1, sigint_default):
    # About 10^4 s simulated: a minute or more of wall time uninterrupted.
    before = signal.getsignal(signal.SIGINT)
    seen = []
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as e:
            ex1.simulate(t_end="10000 s", sample="10 s",
                         discretisation_error=False, progress=seen.append)
    finally:
        timer.cancel()
    wall = time.monotonic() - t0
    assert wall < 20, "stopped %.1f s after the start" % wall
    r = e.value.result
    assert r.completed is False and "stopped on request" in r.error
    h = r.history()
    assert 0 < h.t[-1] < 10000
    assert signal.getsignal(signal.SIGINT) is before
    # Progress was reported while it ran, and stopped with the run.
    assert seen and seen[-1].done < 10000


def test_sigint_with_a_handler_of_ones_own(ex1):
    calls = []
    old = signal.signal(signal.SIGINT, lambda sig, frame: calls.append(sig))
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    try:
        timer.start()
        with pytest.raises(towstab.Cancelled) as e:
            ex1.simulate(t_end="10000 s", sample="10 s",
                         discretisation_error=False)
        assert calls == [signal.SIGINT]
        assert e.value.result.completed is False
        assert "SIGINT" in e.value.message
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, old)


def test_short_runs_unchanged(ex1, sigint_default):
    # No callable, nothing interrupted: results as before, the handler
    # back in place.
    before = signal.getsignal(signal.SIGINT)
    r = ex1.equilibrium()
    assert r.completed is True
    assert signal.getsignal(signal.SIGINT) is before


SUB = os.path.join(ROOT, "examples/kamman_ex1_submerged.yaml")


@pytest.fixture(scope="module")
def sub():
    return towstab.Scene.load(SUB)


def _interrupted(run, after):
    """Run `run` with SIGINT sent after `after` s: the KeyboardInterrupt
    it raises, and the wall time it took."""
    timer = threading.Timer(after, os.kill, (os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as e:
            run()
    finally:
        timer.cancel()
    return e.value, time.monotonic() - t0


def test_sigint_stops_a_newton_equilibrium(sub, sigint_default):
    # 2000 links by Newton: a Jacobian of 4000 columns, several seconds
    # uninterrupted; stopped at its next column (or after its last LU).
    before = signal.getsignal(signal.SIGINT)
    e, wall = _interrupted(lambda: sub.equilibrium(
        links=2000, equilibrium_method="newton",
        discretisation_error=False), 0.5)
    assert wall < 20, "stopped %.1f s after the start" % wall
    r = e.result
    assert r.completed is False and r.trustworthy is False
    assert "stopped on request" in r.error
    # The state reached so far, with its residual.
    assert r.method == "newton" and r.residual >= 0
    assert r.converged is False and len(r.nodes) == 2001
    assert signal.getsignal(signal.SIGINT) is before


def test_sigint_stops_large_modes(sub, sigint_default):
    # 20000 links: the equilibrium and the sparse linear model take about
    # a second, ARPACK and the rightmost search many more.
    e, wall = _interrupted(lambda: sub.modes(
        links=20000, discretisation_error=False), 1.5)
    assert wall < 30, "stopped %.1f s after the start" % wall
    r = e.result
    assert r.completed is False and "stopped on request" in r.error
    # The equilibrium was finished before the stop: kept, converged.
    assert r.equilibrium.converged is True
    assert "modes" not in r or not r["modes"]


def test_progress_of_modes_and_stop(sub, monkeypatch):
    # The stages report in order; a true return in the eigensolve stops
    # it (Cancelled), the equilibrium kept.
    monkeypatch.setattr(towstab, "PROGRESS_INTERVAL", 0.0)
    seen = []

    def stop_in_eigensolve(p):
        seen.append((p.what, p.done, p.total, p.unit))
        return p.what == "eigensolve" and p.done >= 5

    with pytest.raises(towstab.Cancelled) as e:
        sub.modes(links=2000, discretisation_error=False,
                  progress=stop_in_eigensolve)
    whats = [w for w, *_ in seen]
    assert whats[0] == "equilibrium" and "eigensolve" in whats
    last = seen[-1]
    assert last[0] == "eigensolve" and last[1] == 5
    assert last[3] == "operator applications" and math.isnan(last[2])
    assert "after 5 operator applications" in e.value.message
    assert e.value.result.equilibrium.converged is True
