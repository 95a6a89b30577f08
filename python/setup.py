"""Build of the bijparam Python package: one C extension, bijparam._native,
compiled from bijparam.h (the library is the header) and examples/bp_gltf.h
(its glTF reader and writer) on the CPython and numpy C APIs.  The build needs a C compiler and numpy's headers, nothing
else.

The headers are taken from the repository (this folder's parent, and its
examples/) or from this folder (an sdist carries copies: see sdist
below)."""
import os
import shutil

from setuptools import Extension, setup
from setuptools.command.sdist import sdist

HERE = os.path.dirname(os.path.abspath(__file__))


def header_dir():
    for d in (HERE, os.path.dirname(HERE)):
        if os.path.isfile(os.path.join(d, "bijparam.h")):
            return d
    raise SystemExit("bijparam: bijparam.h not found next to setup.py or in its parent folder")


def gltf_dir():
    """examples/bp_gltf.h, the glTF reader and writer beside the library."""
    for d in (HERE, os.path.join(os.path.dirname(HERE), "examples")):
        if os.path.isfile(os.path.join(d, "bp_gltf.h")):
            return d
    raise SystemExit("bijparam: bp_gltf.h not found next to setup.py or in ../examples")


def version():
    with open(os.path.join(header_dir(), "bijparam.h"), encoding="utf-8") as f:
        for line in f:
            if line.startswith("#define BP_VERSION_STRING"):
                return line.split('"')[1]
    raise SystemExit("bijparam: no BP_VERSION_STRING in bijparam.h")


class Sdist(sdist):
    """An sdist stands alone: it carries the headers beside setup.py."""

    def make_release_tree(self, base_dir, files):
        super().make_release_tree(base_dir, files)
        shutil.copy(os.path.join(header_dir(), "bijparam.h"), os.path.join(base_dir, "bijparam.h"))
        shutil.copy(os.path.join(gltf_dir(), "bp_gltf.h"), os.path.join(base_dir, "bp_gltf.h"))


class NumpyInclude:
    """numpy's include folder, asked for only when the compiler needs it."""

    def __str__(self):
        import numpy
        return numpy.get_include()

    def __fspath__(self):
        return str(self)


# -g0: Python's own flags ask for debug information, which makes the
# 21,000-line header a fifth slower to compile.  -fno-wrapv: they also
# define signed overflow to wrap (CPython's own code relies on it), which
# keeps gcc from reasoning about the header's loop counters -- 8% more
# instructions on camel_b at 1024 (callgrind); the library never
# overflows a signed integer (make check runs it under UBSan).
# BIJPARAM_CFLAGS adds flags
# after it (make python adds -Wextra -Werror, make check builds the
# extension with -g -fsanitize=address through it).
extra = os.environ.get("BIJPARAM_CFLAGS", "").split()

setup(
    name="bijparam",
    version=version(),
    description="Bijective free-boundary UV parameterization (bijparam.h) for numpy",
    long_description=open(os.path.join(HERE, "README.md"), encoding="utf-8").read(),
    long_description_content_type="text/markdown",
    license="MIT",
    packages=["bijparam"],
    python_requires=">=3.8",
    install_requires=["numpy"],
    ext_modules=[
        Extension(
            "bijparam._native",
            sources=["bijparam/_native.c"],
            include_dirs=[header_dir(), gltf_dir(), str(NumpyInclude())],
            extra_compile_args=["-O2", "-g0", "-fno-wrapv", "-pthread"] + extra,
            extra_link_args=["-pthread"] + extra,
            libraries=["m"],
        )
    ],
    cmdclass={"sdist": Sdist},
)
