"""Built-in robots: ``load(name)`` and ``names()``."""
