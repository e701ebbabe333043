"""Bundle block adjustment: Levenberg–Marquardt with the points eliminated.

Public API
----------
:class:`BundleProblem`, :class:`BundleConfig`, :class:`BundleResult`,
:func:`bundle_adjust`, :func:`adjust_with_outlier_rejection`,
:func:`adjust_orientation`, :func:`observation_jacobians`,
:data:`INTRINSIC_NAMES`. Conventions: :mod:`truortho.core.geometry`; model,
unknowns and datum: :mod:`.problem`; derivatives: :mod:`.jacobians`.
"""

from .adapter import OrientationBundleConfig, adjust_orientation
from .jacobians import observation_jacobians
from .options import BundleConfig, BundleResult
from .outliers import adjust_with_outlier_rejection
from .problem import INTRINSIC_NAMES, BundleProblem
from .solver import bundle_adjust

__all__ = [
    "INTRINSIC_NAMES",
    "BundleConfig",
    "BundleProblem",
    "BundleResult",
    "OrientationBundleConfig",
    "adjust_orientation",
    "adjust_with_outlier_rejection",
    "bundle_adjust",
    "observation_jacobians",
]
