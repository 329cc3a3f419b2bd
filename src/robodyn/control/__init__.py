"""Model-based control: controllers ``(t, q, v) -> tau`` and joint-space references.

    import robodyn as rd
    from robodyn import control
    ref = control.quintic(q0, q1, duration=2.0)
    ctrl = control.ComputedTorque(model, ref, kp=100.0, kd=20.0)
    traj = rd.simulate(model, q0, v0, 3.0, 1e-3, controller=ctrl)
"""

from .controllers import (AdaptiveSlotineLi, ComputedTorque, Controller, JointPD, PDGravity, PIDGravity, SlotineLi,
                          TaskSpacePD)
from .constrained import ConstrainedForcePosition
from .interaction import (Admittance, CartesianImpedance, HybridForcePosition, OperationalSpace,
                          WorkspaceComputedTorque, rotation_vector)
from .references import PointToPoint, Sampled, cubic, quintic
from .whole_body import WholeBodyID, whole_body_inverse_dynamics

__all__ = ["Controller", "PDGravity", "PIDGravity", "ComputedTorque", "TaskSpacePD", "SlotineLi", "AdaptiveSlotineLi",
           "JointPD", "CartesianImpedance", "HybridForcePosition", "ConstrainedForcePosition",
           "OperationalSpace", "Admittance",
           "WorkspaceComputedTorque", "rotation_vector", "WholeBodyID", "whole_body_inverse_dynamics", "PointToPoint",
           "Sampled", "cubic", "quintic"]
