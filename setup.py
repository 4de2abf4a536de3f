"""Build of the compiled parts (C++17, pybind11):

- ``freefloat.dynamics._core``: the GJM layer (cpp/core.cpp), Eigen headers only;
- ``freefloat.dynamics._sim``: the simulation loop (cpp/sim_module.cpp) on Pinocchio's C++
  algorithms, compiled against the headers the ``pin`` wheel ships (a build requirement; nothing
  is linked: the loop uses header-only templates).

Everything else about the package is in pyproject.toml."""

import sys
from pathlib import Path

from pybind11.setup_helpers import Pybind11Extension, build_ext
from setuptools import setup


def cmeel_include(marker: str) -> str:
    """The ``cmeel.prefix/include`` folder (or its ``eigen3``) on sys.path that holds ``marker``."""
    for entry in sys.path:
        for candidate in (Path(entry) / "cmeel.prefix" / "include", Path(entry) / "cmeel.prefix" / "include" / "eigen3"):
            if (candidate / marker).is_file():
                return str(candidate)
    raise RuntimeError(f"{marker} not found under any cmeel.prefix/include: install the build requirements "
                       "(cmeel-eigen, pin)")


FLAGS = ["-O3", "-DEIGEN_NO_DEBUG", "-DNDEBUG"]
# Pinocchio's joint variant needs larger Boost.MPL limits than Boost's preprocessed defaults.
PINOCCHIO_FLAGS = ["-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
                   "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12"]

setup(
    ext_modules=[
        Pybind11Extension(
            "freefloat.dynamics._core",
            ["cpp/core.cpp"],
            depends=[str(path) for path in sorted(Path("cpp").glob("*.hpp"))],
            include_dirs=[cmeel_include("Eigen/Core"), "cpp"],
            cxx_std=17,
            extra_compile_args=FLAGS,
        ),
        Pybind11Extension(
            "freefloat.dynamics._sim",
            ["cpp/sim_module.cpp"],
            depends=[str(path) for path in sorted(Path("cpp/sim").glob("*.hpp"))] + ["cpp/py_arrays.hpp"],
            include_dirs=[cmeel_include("pinocchio/algorithm/aba.hpp"), cmeel_include("Eigen/Core"), "cpp"],
            cxx_std=17,
            extra_compile_args=FLAGS + PINOCCHIO_FLAGS,
        ),
    ],
    cmdclass={"build_ext": build_ext},
)
