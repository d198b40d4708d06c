"""Large steps for spring networks: fast mass-springs, XPBD and strain limiting.

- :mod:`~course_lib.largestep.base`: :class:`SpringSolver`, the checks every solver shares;
- :mod:`~course_lib.largestep.local_global`: :class:`FastMassSpring`, implicit Euler by
  local/global iterations (Liu et al. 2013) or L-BFGS (Liu, Bouaziz & Kavan 2017) on one
  constant factored matrix (:class:`FactorCache` counts the factorizations);
- :mod:`~course_lib.largestep.constraints`: springs as distance constraints in sets that
  share no particle (:func:`independent_sets`, :class:`ColouredSprings`);
- :mod:`~course_lib.largestep.xpbd`: :class:`XPBD` (Macklin, Müller & Chentanez 2016)
  with small steps; :mod:`~course_lib.largestep.pbd`: plain :class:`PBD` (Müller et al. 2007);
- :mod:`~course_lib.largestep.attachments`: :class:`LongRangeAttachments` (Kim, Chentanez
  & Müller 2012), tethers from every particle to the pins;
- :mod:`~course_lib.largestep.strain_limit`: :class:`StrainLimiter` (Provot 1995).

Core package: imports NumPy, SciPy and other core modules only.
"""

from .attachments import LongRangeAttachments
from .base import SpringSolver
from .constraints import ColouredSprings, independent_sets
from .local_global import FactorCache, FastMassSpring, laplacian
from .pbd import PBD
from .strain_limit import StrainLimiter
from .xpbd import XPBD, delta_lambda

__all__ = ["PBD", "XPBD", "ColouredSprings", "FactorCache", "FastMassSpring",
           "LongRangeAttachments", "SpringSolver", "StrainLimiter", "delta_lambda",
           "independent_sets", "laplacian"]
