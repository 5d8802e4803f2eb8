"""cffi build script: compiles libvpds's C sources into the extension module vpds._vpds.

The declarations are read from include/vpds.h itself, so the binding cannot drift from it."""
import re
from pathlib import Path

from cffi import FFI

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent.parent  # bindings/python/vpds -> repository root
# The library's sources are compiled into the extension as one translation unit (their static
# names do not clash): setuptools would refuse them as sources outside this directory.
# libvpds/sources.txt: the one list of the library's sources (the Makefile and CMake read it too)
UNITY = "\n".join(f'#include "{name}"' for name in (ROOT / "libvpds" / "sources.txt").read_text().split())



def declarations_from_header(path: Path) -> str:
    """vpds.h as cffi reads it: no comments, no preprocessor lines, no VPDS_API."""
    text = path.read_text()
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    lines = [line for line in text.splitlines()
             if not line.lstrip().startswith("#") and line.strip() not in ('extern "C" {', "}")]
    return "\n".join(lines).replace("VPDS_API ", "")


ffibuilder = FFI()
ffibuilder.cdef(declarations_from_header(ROOT / "include" / "vpds.h"))
# floating-point macros of vpds.h (cffi reads only integer #defines by itself)
ffibuilder.cdef("static const double VPDS_STREAM_TOLERANCE;")
ffibuilder.cdef("static const double VPDS_STREAM_DOMAIN_TOLERANCE;")
ffibuilder.cdef("#define VPDS_ALGORITHM_VERSION ...")
ffibuilder.cdef("#define VPDS_MAX_DIM ...")
ffibuilder.cdef("#define VPDS_TILING_MAX_DIM ...")
# the batched sizing callback that runs Python code (see vpds._core.vpds_py_sizing_batch)
ffibuilder.cdef('''extern "Python" int vpds_py_sizing_batch(const double *x, size_t n, double *r_out,
                                                      void *user);''')
# the domain callback that runs Python code (see vpds.domain.vpds_py_domain)
ffibuilder.cdef('extern "Python" double vpds_py_domain(const double *x, void *user);')
ffibuilder.set_source(
    "vpds._vpds",
    '#include "vpds.h"\n' + UNITY,
    include_dirs=[str(ROOT / "include"), str(ROOT / "libvpds")],
    # the sources the unit includes: a change to one alone rebuilds the extension (setuptools
    # compares the generated file's time only, which a C-only change leaves as it was)
    depends=[str(p) for p in sorted((ROOT / "libvpds").glob("*.[ch]"))] + [str(ROOT / "include" / "vpds.h")],
    # the library's determinism contract: no FMA contraction, no fast-math
    extra_compile_args=["-std=c99", "-O2", "-ffp-contract=off", "-fvisibility=hidden", "-pthread"],
    extra_link_args=["-pthread"],  # vpds_tiling_run's threads
)

if __name__ == "__main__":
    ffibuilder.compile(verbose=True)
