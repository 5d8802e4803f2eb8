"""vpds: maximal Poisson-disk sampling with spatially varying radii, in any dimension.

    >>> import vpds
    >>> engine = vpds.PoissonDisk(2, radius=0.05, rng=1)
    >>> x = engine.fill_space()          # maximal, shape (n, 2)
"""
from ._core import ALGORITHM_VERSION, MAX_DIM, RULES, PoissonDisk, Progressive, SizingGrid
from ._errors import (VpdsDomainError, VpdsError, VpdsSizingError, VpdsStateError, VpdsUnsupportedError,
                      VpdsValueError)
from .domain import Domain, estimate_radius
from .mesh import MeshSampler, MeshSamples, sample_mesh
from ._vpds import ffi as _ffi, lib as _lib

__version__ = _ffi.string(_lib.vpds_version_string()).decode()
#: relative tolerance of the continuous stream: t is an upper bound, conflicts hold at t(1 - eps)
STREAM_TOLERANCE: float = float(_lib.VPDS_STREAM_TOLERANCE)
#: the same for a sampler with a domain
STREAM_DOMAIN_TOLERANCE: float = float(_lib.VPDS_STREAM_DOMAIN_TOLERANCE)
__all__ = ["PoissonDisk", "SizingGrid", "VpdsError", "VpdsValueError", "VpdsSizingError",
           "VpdsUnsupportedError", "VpdsStateError", "RULES", "STREAM_TOLERANCE", "STREAM_DOMAIN_TOLERANCE", "VpdsDomainError", "Domain",
           "Progressive", "estimate_radius", "sample_mesh", "MeshSampler", "MeshSamples", "ALGORITHM_VERSION", "MAX_DIM", "__version__"]
