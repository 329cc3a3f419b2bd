"""Dynamics algorithms: one file per algorithm, each a pure function of the model and state."""
