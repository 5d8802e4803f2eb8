"""The cffi extension built by vpds/_build.py from include/vpds.h: its C functions, structs and
pointers have no Python types, so `lib` and what `ffi` returns are Any. Only `def_extern` is
typed, so that the callbacks it decorates keep their own signatures."""
from typing import Any, Callable, Optional, TypeVar

_F = TypeVar("_F", bound=Callable[..., Any])

class _FFI:
    def def_extern(self, name: Optional[str] = ..., error: Any = ...,
                   onerror: Optional[Callable[..., Any]] = ...) -> Callable[[_F], _F]: ...
    def __getattr__(self, name: str) -> Any: ...

ffi: _FFI
lib: Any
