"""Python callables behind the C library's callbacks: what happens when one raises.

The C library calls a Python sizing (vpds._core.vpds_py_sizing_batch) or domain
(vpds.domain.vpds_py_domain) through cffi. Any exception there — a bug in the callable, a
ValueError it raises on purpose, a KeyboardInterrupt from Ctrl-C — must stop the C run at once
and come back out of the Python call that started it, as itself:

- The callback catches it, keeps it in its owner's slot and returns failure (non-zero from the
  sizing batch, NaN from the domain). The library then stops with VPDS_ERR_SIZING or
  VPDS_ERR_DOMAIN and leaves the sampler as a pause would (include/vpds.h), so calling again
  continues to the points of an uninterrupted run.
- An exception can also escape the callback's body: Ctrl-C is delivered at the next Python
  instruction, which may be the callback's first, before its `try`. The callbacks are declared
  with an `error` value and an `onerror` handler (`escaped`), which finds the owner in the
  callback's frame and keeps the exception there too (cffi would otherwise print "Exception
  ignored from cffi callback" and return 0, i.e. success with unwritten radii).
- Once a slot holds an exception the callback fails at once, without Python work, until the
  binding takes the exception after the C call (`take`) and raises it (`raise_failure`).

Errors the binding finds in what a callable returned (a wrong shape, values that are not
numbers) are `CallbackResultError`s: they are raised as the library's own error
(VpdsSizingError / VpdsDomainError, a ValueError) with that message, from the CallbackResultError.
"""
from __future__ import annotations

from types import TracebackType
from typing import Any, Callable, NoReturn, Optional

import numpy as np
import numpy.typing as npt

from ._errors import _raise
from ._vpds import ffi, lib

__all__ = ["CallbackResultError", "as_values", "keep", "escaped", "take", "raise_failure"]


class CallbackResultError(ValueError):
    """A callable returned something the library cannot use (found by the binding)."""


def as_values(out: Any, n: int, what: str, flat: bool = False) -> npt.NDArray[np.float64]:
    """A callable's result as n float64 values (flat: of any shape holding n values), else a
    CallbackResultError saying why."""
    if out is None:  # np.asarray(None, float) is NaN: say what came back instead
        raise CallbackResultError(f"{what} returned None, not numbers (a missing return?)")
    try:
        v = np.asarray(out, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise CallbackResultError(f"{what} returned {type(out).__name__}, not numbers: {exc}") from None
    if flat:
        v = v.reshape(-1)
    if v.shape != (n,):
        raise CallbackResultError(f"{what} returned shape {v.shape} for {n} point{'s' if n != 1 else ''};"
                                  f" expected ({n},)")
    return v


def keep(user: Any, slot: str, exc: BaseException) -> bool:
    """Keep exc in attribute `slot` of the owner behind the cffi handle `user`, unless the slot
    holds one already (the first wins). False: `user` is not a handle to such an owner."""
    try:
        owner = ffi.from_handle(user)
    except (TypeError, ValueError, RuntimeError):
        return False
    if not hasattr(owner, slot):
        return False
    if getattr(owner, slot) is None:
        setattr(owner, slot, exc)
    return True


def escaped(slot: str) -> Callable[[type[BaseException], BaseException, Optional[TracebackType]], None]:
    """The cffi onerror handler of a callback whose argument `user` is the handle of an owner
    keeping exceptions in attribute `slot`: keep the escaped exception there. cffi then returns
    the callback's `error` value, and prints nothing."""

    def onerror(exc_type: type[BaseException], exc: BaseException, tb: Optional[TracebackType]) -> None:
        while tb is not None:  # the callback's frame is the first (it was called from C)
            user = tb.tb_frame.f_locals.get("user")
            if user is not None and keep(user, slot, exc):
                return None
            tb = tb.tb_next
        return None  # no owner found (never seen): the call still fails, without the exception

    return onerror


def take(owner: Any, slot: str) -> Optional[BaseException]:
    """The exception kept in owner.slot, emptying the slot (None: none, or no owner)."""
    if owner is None:
        return None
    exc = getattr(owner, slot, None)
    if exc is not None:
        setattr(owner, slot, None)
    return exc


def raise_failure(status: int, message: str, cause: Optional[BaseException], where: str) -> NoReturn:
    """Raise the outcome of a C call that failed (status < 0) or whose `where` ("sizing",
    "domain") callable raised (cause): the callable's own exception as itself, with the C status
    and message as a note (Python 3.11+); a CallbackResultError or a C error alone as the
    library's error for the status, with the CallbackResultError's message."""
    if status >= 0:  # the call went on after a callable raised: never seen, but say it
        status = lib.VPDS_ERR_DOMAIN if where == "domain" else lib.VPDS_ERR_SIZING
    if cause is not None and not isinstance(cause, CallbackResultError):
        if hasattr(cause, "add_note"):
            name = ffi.string(lib.vpds_status_string(status)).decode().split(":")[0]
            cause.add_note(f"(raised in the {where} callable, called by libvpds: {name}: {message})")
        raise cause
    if cause is not None:
        # the binding answered NaN to stop the library: its "returned NaN" was not the callable's
        message = message.replace(f"{where} returned NaN at", f"{where} called at", 1)
        message = f"{message}: {cause}" if message else str(cause)
    _raise(status, message, cause)
    raise AssertionError("unreachable")  # _raise always raises
