"""Contacts between the robot and the world: shapes on the bodies, static surfaces, and the
compiled contact solver that :func:`robodyn.simulate` steps with (``contacts=``).

    contacts = rd.contact.Contacts([rd.contact.Sphere("FL_FOOT", 0.02), ...],
                                   surfaces=[rd.contact.Plane(friction=0.8)])
    traj = rd.simulate(model, q0, v0, 2.0, 1e-3, controller, contacts=contacts)
    traj.contact_force        # (N, npairs, 3), world axes

The model (velocity-level time stepping, unilateral contacts, Coulomb cones, impacts) and the
solver are described in :mod:`robodyn.contact.solver`; the shapes in
:mod:`robodyn.contact.geometry`.
"""

from .geometry import BodySphere, Box, Capsule, Contacts, Plane, Point, Sphere, StaticBox, shapes_from_urdf

__all__ = ["Contacts", "Sphere", "Point", "Box", "Capsule", "Plane", "StaticBox", "BodySphere", "shapes_from_urdf"]
