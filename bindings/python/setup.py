# The C library is compiled into the extension module by cffi (vpds/_build.py): `pip install`
# needs no separate build step and no LD_LIBRARY_PATH.
from setuptools import setup

setup(cffi_modules=["vpds/_build.py:ffibuilder"])
