"""``rd.warmup()``: it reaches every public function with compiled code and reports progress."""

import inspect

import numpy as np

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
