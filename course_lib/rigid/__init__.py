"""Rigid bodies: Baraff's state, torque-free spin, contact by impulses, and magnets.

The package follows Baraff (2001), "Physically Based Modeling: Rigid Body Simulation"
(SIGGRAPH course notes):

- :mod:`~course_lib.rigid.quaternion`: orientations as unit quaternions, the renormalised
  quaternion step;
- :mod:`~course_lib.rigid.inertia`: inertia tensors of a box, a sphere and a cylinder, in
  the body and the world frame;
- :mod:`~course_lib.rigid.free`: torque-free motion (Euler's equations) by six methods,
  :func:`free_body`; :mod:`~course_lib.rigid.exact`: its exact solution by Jacobi elliptic
  functions and its period;
- :mod:`~course_lib.rigid.body`: ``N`` bodies as arrays of ``(x, q, P, L)``, their step
  and a simulation loop;
- :mod:`~course_lib.rigid.contact`: impulses with restitution and Coulomb friction
  (ground plane, sphere pairs);
- :mod:`~course_lib.rigid.magnets`: point dipoles, exact force, torque and energy.

Core layer: imports NumPy, SciPy and the core only.
"""

from . import body, contact, exact, free, inertia, magnets, quaternion
from .body import Bodies, Run, make, simulate, step
from .free import METHODS, free_body

__all__ = ["METHODS", "Bodies", "Run", "body", "contact", "exact", "free", "free_body", "inertia",
           "magnets", "make", "quaternion", "simulate", "step"]
