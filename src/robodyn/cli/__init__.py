"""The ``robodyn`` command line: ``main`` parses and dispatches (``main.py``); each command
family lives in its own module (``model.py``: info, demo, bench; ``simulation.py``: simulate,
torques; ``identification.py``: excite, identify; ``symbolic.py``: derive), sharing the
helpers of ``common.py``."""

from .main import main

__all__ = ["main"]
