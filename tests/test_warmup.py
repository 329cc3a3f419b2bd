"""``rd.warmup()``: it reaches every public function with compiled code and reports progress."""

import inspect

import numpy as np
import pytest

import robodyn as rd
from robodyn import _warmup as W


def test_every_public_algorithm_and_the_simulation_are_warmed_up():
    names = {name.split(" (")[0] for name, _ in W.steps()}
    functions = {n for n, module in rd._LAZY.items() if not inspect.isclass(getattr(rd, n))}
    assert functions - names == set()
    assert {"simulate", "rollout"} <= names


def test_progress_reports_each_step_then_the_end(monkeypatch):
    calls = []
    monkeypatch.setattr(W, "steps", lambda: [("a", lambda: calls.append("a")), ("b", lambda: calls.append("b"))])
    seen = []
    rd.warmup(progress=lambda done, total, name: seen.append((done, total, name)))
    assert calls == ["a", "b"]
    assert seen == [(0, 2, "a"), (1, 2, "b"), (2, 2, "")]


def test_warmup_runs_real_steps_silently(monkeypatch):
    """``rd.warmup()`` with its defaults (no progress callback) runs real steps, each once and in
    order; three of them keep it cheap."""
    chosen = ["rnea (fixed base, one state)", "aba (floating base, batch)", "crba (floating base, one state)"]
    real = dict(W.steps())
    ran = []

    def recorded(name):
        def call():
            ran.append((name, real[name]()))
        return call

    monkeypatch.setattr(W, "steps", lambda: [(name, recorded(name)) for name in chosen])
    assert rd.warmup() is None
    assert [name for name, _ in ran] == chosen
    for name, result in ran:
        assert np.all(np.isfinite(result)), name


def test_compiling_in_processes_then_loading_here(monkeypatch):
    """``processes=2`` when the first step compiled something: child processes take the groups
    of the other steps (a function's together), each group reported as it starts; then every
    step runs here, from the cache."""
    ran, seen = [], []
    real = W.steps

    def recorded():
        return [(name, lambda name=name, call=call: ran.append(name) or call()) for name, call in real()]

    monkeypatch.setattr(W, "steps", recorded)
    monkeypatch.setattr(W, "_compiles", lambda call: (call(), True)[1])  # as on a first run
    rd.warmup(progress=lambda done, total, name: seen.append((done, total, name)), only=["rnea", "crba"], processes=2)
    names = [name for name, _ in real() if name.split(" ")[0] in ("rnea", "crba")]
    assert ran == names  # here, the first before the processes
    assert seen[0] == (0, len(names), names[0]) and seen[-1] == (len(names), len(names), "")
    assert sorted(name for _, _, name in seen[1:-1]) == ["crba (fixed base, one state)", "rnea (fixed base, batch)"]
    assert seen[1][0] == 1 and all(t == len(names) for _, t, _ in seen)
    assert [done for done, _, _ in seen] == sorted(done for done, _, _ in seen)


def test_processes_start_at_the_first_step_that_compiles(monkeypatch):
    """Steps whose code this process or the cache has run here (new processes would take
    longer); from the first that compiles (a function Numba does not cache), the steps after
    it go to the processes."""
    import numba

    started = []
    monkeypatch.setattr(W, "_compile_in_processes", lambda names, *args: started.append(names))
    W.steps()[0][1]()  # its kernels compiled or loaded
    rd.warmup(only=["rnea"], processes=2)
    assert started == []
    fresh = numba.njit(lambda x: x + 1)
    ran = []
    monkeypatch.setattr(W, "steps", lambda: [("old", lambda: ran.append("old")), ("new", lambda: ran.append(fresh(1))),
                                             ("next", lambda: ran.append("next")), ("last", lambda: ran.append("last"))])
    rd.warmup(processes=2)
    assert started == [["next", "last"]] and ran == ["old", 2, "next", "last"]


def test_a_failing_compiling_process_is_an_error_naming_its_step():
    with pytest.raises(RuntimeError, match=r"compiling 'no such step' stopped \(exit code 1\): .*KeyError"):
        W._compile_in_processes(["no such step", "rnea (fixed base, one state)"], 2, None)
    with pytest.raises(ValueError, match="processes: expected an integer >= 1, got 0"):
        rd.warmup(processes=0)


def test_groups_keep_a_functions_steps_together_and_the_simulations_first():
    names = [name for name, _ in W.steps()]
    groups = W._groups(names)
    assert sorted(sum(groups, [])) == sorted(names)
    assert groups[0] == [name for name in names if "contacts" in name] and len(groups[0]) == 5
    assert not any("contacts" in name for g in groups[1:] for name in g)
    assert groups[1] == [name for name in names if name.startswith("simulate") and "contacts" not in name]
    rnea = [g for g in groups if g[0].startswith("rnea (")]
    assert len(rnea) == 1 and len(rnea[0]) == 6  # fixed and floating base, one state and batch; the mimic ones
