"""Errors of libvpds as Python exceptions, and the validate-then-create of its C objects."""
from __future__ import annotations

from typing import Any, NoReturn, Optional

from ._vpds import ffi, lib

__all__ = ["VpdsError", "VpdsValueError", "VpdsSizingError", "VpdsUnsupportedError",
           "VpdsDomainError", "VpdsStateError", "created"]


class VpdsError(RuntimeError):
    """An error status from libvpds, with the library's message (argument, value, why)."""

    def __init__(self, status: int, message: str) -> None:
        self.status = status
        name = ffi.string(lib.vpds_status_string(status)).decode().split(":")[0]
        super().__init__(f"{name}: {message}")


class VpdsValueError(VpdsError, ValueError):
    """Invalid arguments (VPDS_ERR_INVALID_ARGUMENT, VPDS_ERR_OVERFLOW, VPDS_ERR_BAD_DESCRIPTOR)."""


class VpdsSizingError(VpdsError, ValueError):
    """The sizing function returned a bad radius or broke its declared Lipschitz constant."""


class VpdsUnsupportedError(VpdsError, NotImplementedError):
    """A capability this version of libvpds does not provide yet."""


class VpdsDomainError(VpdsError, ValueError):
    """The domain function returned NaN, is not 1-Lipschitz, or its domain is empty."""


class VpdsStateError(VpdsError):
    """The call is not valid in the sampler's current state (e.g. refining to a larger t)."""


def _raise(status: int, message: str, cause: Optional[BaseException] = None) -> NoReturn:
    if status == lib.VPDS_ERR_OUT_OF_MEMORY:
        raise MemoryError(message)
    cls = {lib.VPDS_ERR_INVALID_ARGUMENT: VpdsValueError, lib.VPDS_ERR_OVERFLOW: VpdsValueError,
           lib.VPDS_ERR_BAD_DESCRIPTOR: VpdsValueError, lib.VPDS_ERR_SIZING: VpdsSizingError,
           lib.VPDS_ERR_LIPSCHITZ: VpdsSizingError, lib.VPDS_ERR_UNSUPPORTED: VpdsUnsupportedError,
           lib.VPDS_ERR_STATE: VpdsStateError,
           lib.VPDS_ERR_DOMAIN: VpdsDomainError}.get(status, VpdsError)
    raise cls(status, message) from cause


def created(validate: Any, create: Any, destroy: Any, ctype: str, *args: Any) -> Any:
    """A C object: validate(*args, msg, cap) says why it is refused (raised with the C message),
    create(*args, &out) makes it, and destroy frees it when Python collects it."""
    msg = ffi.new("char[]", 1024)
    st = validate(*args, msg, 1024)
    if st != lib.VPDS_OK:
        _raise(st, ffi.string(msg).decode())
    out = ffi.new(f"{ctype} **")
    st = create(*args, out)
    if st != lib.VPDS_OK:
        _raise(st, f"{ctype}: create failed")
    return ffi.gc(out[0], destroy)
