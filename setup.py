"""Build of the compiled core ``freefloat.dynamics._core`` (one C++17 translation unit, pybind11
and Eigen headers only). Everything else about the package is in pyproject.toml."""

import sys
from pathlib import Path

from pybind11.setup_helpers import Pybind11Extension, build_ext
from setuptools import setup


def eigen_include() -> str:
    """Eigen's headers from ``cmeel-eigen`` (a build requirement; the same Eigen ``pin`` is built with)."""
    for entry in sys.path:
        candidate = Path(entry) / "cmeel.prefix" / "include" / "eigen3"
        if (candidate / "Eigen" / "Core").is_file():
            return str(candidate)
    raise RuntimeError("Eigen headers not found: install the build requirement cmeel-eigen")


setup(
    ext_modules=[
        Pybind11Extension(
            "freefloat.dynamics._core",
            ["cpp/core.cpp"],
            depends=[str(path) for path in sorted(Path("cpp").glob("*.hpp"))],
            include_dirs=[eigen_include(), "cpp"],
            cxx_std=17,
            extra_compile_args=["-O3", "-DEIGEN_NO_DEBUG"],
        )
    ],
    cmdclass={"build_ext": build_ext},
)
