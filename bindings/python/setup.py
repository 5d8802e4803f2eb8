# The C library is compiled into the extension module by cffi (vpds/_build.py): `pip install`
# needs no separate build step and no LD_LIBRARY_PATH. The version is the C library's, read
# from include/vpds.h; the extension uses only the limited API, so one wheel (abi3) serves
# every CPython from 3.9.
import re
from pathlib import Path

from setuptools import setup

HEADER = Path(__file__).resolve().parent.parent.parent / "include" / "vpds.h"
VERSION = ".".join(re.findall(r"#define VPDS_VERSION_(?:MAJOR|MINOR|PATCH) (\d+)", HEADER.read_text()))

setup(version=VERSION, cffi_modules=["vpds/_build.py:ffibuilder"],
      options={"bdist_wheel": {"py_limited_api": "cp39"}})
