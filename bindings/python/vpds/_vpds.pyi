"""The cffi extension built by vpds/_build.py from include/vpds.h. Its C functions, structs and
pointers have no Python types, so `lib` and what `ffi` gives are Any, but for the bytes of a C
string and `def_extern` (typed so that the callbacks it decorates keep their signatures)."""
from typing import Any, Callable, Optional, TypeVar

_F = TypeVar("_F", bound=Callable[..., Any])

class _FFI:
    def string(self, cdata: Any, maxlen: int = ...) -> bytes: ...
    def def_extern(self, name: Optional[str] = ..., error: Any = ...,
                   onerror: Optional[Callable[..., Any]] = ...) -> Callable[[_F], _F]: ...
    def __getattr__(self, name: str) -> Any: ...

ffi: _FFI
lib: Any
