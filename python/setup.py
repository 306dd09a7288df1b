"""pip install ./python: the atmos package built against an installed atmos (found by
pkg-config; `make install PREFIX=...` and PKG_CONFIG_PATH=PREFIX/lib/pkgconfig). Offline, with
Debian's python3-cffi, python3-numpy and python3-setuptools:

    pip install --no-build-isolation ./python
"""
from setuptools import setup

setup(
    name="atmos",
    version="0.2.0",
    description="Physically based rendering of atmospheric phenomena (bindings to libatmos)",
    packages=["atmos"],
    python_requires=">=3.10",
    setup_requires=["cffi>=1.12"],
    install_requires=["cffi>=1.12", "numpy"],
    cffi_modules=["atmos/_build_ffi.py:ffibuilder"],
    zip_safe=False,
)
