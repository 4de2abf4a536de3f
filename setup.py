"""Build of the compiled parts (C++17, pybind11), from cpp/, a folder per concept, each .cpp one
translation unit beside the header it defines:

- ``cpp/gjm/``: the GJM quantities (gjm.cpp) and the hand-built models with their tree-sparse
  solver (models.cpp);
- ``cpp/chains/``: Orsino's closed chains, their point evaluations and forward dynamics
  (mechanism.cpp) and their inverse dynamics and assembly (inverse.cpp);
- ``cpp/sim/``: the compiled loops: the robot loop (simulation.cpp: the loop of loop.hpp and its
  factory), its closed plant (closures.cpp), the two-hand law (loop_detumbling_law.cpp), the
  generalized Jacobian (pin_generalized_jacobian.cpp) and the detumbling solver (detumbling.cpp),
  which call Pinocchio through sim/pin_plant.hpp, defined in pin_plant.cpp, the one unit that
  includes Pinocchio's headers; and the closed-chain loop (chain_loop.cpp), which includes none;
- ``cpp/bindings/``: pybind11 only, the modules' bindings: core.cpp, sim.cpp, and chains.cpp
  (the closed chains' classes).

Two extension modules: ``freefloat.dynamics._core`` (bindings/core.cpp, gjm/) and
``freefloat.dynamics._sim`` (bindings/sim.cpp, sim/ but the closed-chain loop), both with the
closed chains (bindings/chains.cpp, chains/, sim/chain_loop.cpp), whose objects are compiled once.

The robot loop is compiled against the headers of the ``libpinocchio`` wheel (a build requirement)
and linked to its ``libpinocchio_default``, which holds the algorithms already compiled (explicit
template instantiation). What remains of the compile is parsing and instantiating Pinocchio's model
classes, Eigen and pybind11, and the compiler keeps all of it in memory until a unit ends: each
unit holds one concern, so that each peaks under 0.9 GiB but the one that includes Pinocchio
(whose headers alone take 0.6 GiB). The units run one per core, started only while their
measured peaks (:data:`UNIT_MEMORY`) fit in the memory budget (``FREEFLOAT_BUILD_MEMORY``, else
:data:`MEMORY_PER_JOB` per compiler process within :data:`MEMORY_SHARE` of the memory available;
setup_schedule.py), which also prints each unit as it starts and ends, with its time, where the
user sees it (pip and uv hide a build's own output). The robot loop's units are compiled at -O1
(:data:`OPTIMIZATION`): its time is in libpinocchio_default, and every scene measured ran as fast
as at -O3; the numerics stay at -O3 (the closed chains 12-49 % slower at -O2). docs/bench.md,
"The build", has the measurements.

Objects are kept in ``build/cpp/<configuration>/`` of the source tree (ignored by git), also by an
editable install, whose own build folders are temporary: reinstalling with another extra, or
after a Python-only change, compiles nothing and only links. An object is recompiled when its
source or a project header it includes (from g++'s dependency file) is newer, or the
configuration changes (compiler, flags, Python, pybind11, Pinocchio or Eigen version: another
folder).

The wheel requires the exact ``libpinocchio`` it was built against (the module links to its
library); everything else about the package is in pyproject.toml."""

import hashlib
import importlib.util
import json
import os
import platform
import subprocess
import sys
import sysconfig
import tempfile
import time
from importlib.metadata import version
from pathlib import Path

from pybind11.setup_helpers import Pybind11Extension
from pybind11.setup_helpers import build_ext as pybind11_build_ext
from setuptools import setup

ROOT = Path(__file__).resolve().parent


def load_schedule():
    """setup_schedule.py beside this file (a build does not put this folder on sys.path)."""
    spec = importlib.util.spec_from_file_location("setup_schedule", ROOT / "setup_schedule.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


schedule = load_schedule()

# The runtime dependencies are listed here rather than in pyproject.toml because one of them is
# only known at build time: the libpinocchio this build links to.
DEPENDENCIES = [
    "pin>=4.1,<5",
    "example-robot-data>=6.0",
    "yourdfpy>=0.0.56",
    "numpy>=2.0",
    "scipy>=1.13",
    "meshcat>=0.3.2",
    "matplotlib>=3.10.7",
    "tqdm>=4.60",
    "threadpoolctl>=3.1",
]


def cmeel_prefix(marker: str) -> Path:
    """The ``cmeel.prefix`` folder on sys.path whose ``include`` holds ``marker``."""
    for entry in sys.path:
        prefix = Path(entry) / "cmeel.prefix"
        for include in (prefix / "include", prefix / "include" / "eigen3"):
            if (include / marker).is_file():
                return prefix
    raise RuntimeError(f"{marker} not found under any cmeel.prefix/include: install the build requirements "
                       "(cmeel-eigen, libpinocchio)")


PINOCCHIO = cmeel_prefix("pinocchio/algorithm/aba.hpp")
EIGEN = cmeel_prefix("Eigen/Core") / "include" / "eigen3"

# -O3: at -O2 the build takes 16 % less time but the closed-chain loop runs 12-49 % slower (the
# robot loop as fast). Third-party headers are system headers: no warnings from them, and g++'s
# dependency files list only the project's own headers.
FLAGS = ["-O3", "-DEIGEN_NO_DEBUG", "-DNDEBUG", "-isystem", str(EIGEN)]
# Pinocchio's joint variant needs larger Boost.MPL limits than Boost's preprocessed defaults, and
# PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION declares the algorithms libpinocchio_default compiles.
PINOCCHIO_FLAGS = ["-isystem", str(PINOCCHIO / "include"), "-DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION",
                   "-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
                   "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12"]
# The order units start in: the order whose schedule (setup_schedule.run_within, 2 compilers within
# 2 GB) ends soonest with the units' measured times, each varied by up to 12 %; Pinocchio's unit
# first, beside the small ones that fit with it. The kernel's two small units (4-5 s of CPU
# together, 0.17 and 0.09 GB) end the list.
ORDER = ["cpp/sim/pin_plant.cpp", "cpp/bindings/core.cpp", "cpp/chains/mechanism.cpp", "cpp/sim/detumbling.cpp",
         "cpp/sim/closures.cpp", "cpp/sim/chain_loop.cpp", "cpp/bindings/sim.cpp", "cpp/sim/pin_generalized_jacobian.cpp",
         "cpp/bindings/chains.cpp", "cpp/chains/inverse.cpp", "cpp/sim/loop_detumbling_law.cpp", "cpp/gjm/models.cpp",
         "cpp/gjm/gjm.cpp", "cpp/sim/simulation.cpp", "cpp/kernel/kernel.cpp", "cpp/kernel/lanes_avx2.cpp"]
# Optimisation level per translation unit, after FLAGS' -O3 (see the module docstring).
OPTIMIZATION = {"cpp/sim/pin_plant.cpp": "-O1", "cpp/sim/simulation.cpp": "-O1", "cpp/sim/closures.cpp": "-O1",
                "cpp/sim/loop_detumbling_law.cpp": "-O1", "cpp/sim/pin_generalized_jacobian.cpp": "-O1",
                "cpp/bindings/sim.cpp": "-O1"}
# Arithmetic and instruction set per translation unit: the dynamics kernel's units round every
# product and sum on its own (no fused multiply-add, which the compiler would use where the target
# has it), so that a state in a lane of the lockstep gets the very numbers it gets alone; its AVX2
# copy, which it calls only on a CPU that has AVX2 (cpp/kernel/isa.hpp), is a second baseline copy
# on other platforms.
UNIT_FLAGS = {"cpp/kernel/kernel.cpp": "-ffp-contract=off",
              "cpp/kernel/lanes_avx2.cpp": "-ffp-contract=off"
              + (" -mavx2" if platform.machine().lower() in ("x86_64", "amd64") else "")}
# Peak memory of each unit's compile at its flags (bytes: g++ 12's maximum resident set, as the
# build ran it, docs/bench.md "The build"); a unit not listed counts as the largest.
UNIT_MEMORY = {"cpp/sim/pin_plant.cpp": 1.25e9, "cpp/bindings/sim.cpp": 1.04e9, "cpp/bindings/chains.cpp": 0.78e9,
               "cpp/chains/inverse.cpp": 0.71e9, "cpp/sim/detumbling.cpp": 0.69e9, "cpp/chains/mechanism.cpp": 0.66e9,
               "cpp/bindings/core.cpp": 0.64e9, "cpp/sim/loop_detumbling_law.cpp": 0.62e9, "cpp/gjm/models.cpp": 0.57e9,
               "cpp/sim/closures.cpp": 0.51e9, "cpp/gjm/gjm.cpp": 0.50e9, "cpp/sim/chain_loop.cpp": 0.50e9,
               "cpp/sim/simulation.cpp": 0.52e9, "cpp/sim/pin_generalized_jacobian.cpp": 0.37e9,
               "cpp/kernel/kernel.cpp": 0.17e9, "cpp/kernel/lanes_avx2.cpp": 0.09e9}
# The memory budget of the units compiling at once, unless FREEFLOAT_BUILD_MEMORY (bytes) sets it:
# MEMORY_PER_JOB per compiler process, within MEMORY_SHARE of the memory available (never more than
# the memory available). A unit larger than the budget compiles alone. On 2 cores the budget is
# 2 GB: Pinocchio's unit compiles beside the units that fit with it (all but bindings/sim.cpp and
# bindings/chains.cpp), and the compile of the ten units before the layout by concept took 50.6 s
# on 2 idle cores in a `pip install .` (docs/bench.md, "The build").
MEMORY_PER_JOB = 1e9
MEMORY_SHARE = 0.8


class BuildExt(pybind11_build_ext):
    """Compiles the objects of every extension in one pool (one job per core, or
    ``FREEFLOAT_BUILD_JOBS``, within the memory budget), keeps them in
    ``build/cpp/<configuration>/`` and reuses the fresh ones; then links each extension."""

    def build_extensions(self) -> None:
        self.check_extensions_list(self.extensions)
        self.object_dir = ROOT / "build" / "cpp" / self.configuration()
        jobs = list({source: (ext, source) for ext in self.extensions for source in ext.sources}.values())
        jobs.sort(key=lambda job: ORDER.index(job[1]) if job[1] in ORDER else len(ORDER))
        stale = [job for job in jobs if self.force or not self.fresh(job[1], self.object_of(job[1]))]
        workers = max(1, int(setting("FREEFLOAT_BUILD_JOBS", "a number of compiler processes, e.g. 2")
                             or self.parallel or os.cpu_count() or 1))
        budget = schedule.memory_budget(workers, available_memory(), MEMORY_PER_JOB, MEMORY_SHARE,
                                        setting("FREEFLOAT_BUILD_MEMORY", "bytes, e.g. 2e9"))
        out = schedule.terminal()
        try:
            progress = schedule.Progress(out, budget, workers)
            progress.plan(len(stale), len(jobs) - len(stale))

            def compile_timed(job) -> None:
                begin = time.perf_counter()
                try:
                    self.compile_unit(*job)
                except BaseException:
                    progress.ended(job[1], time.perf_counter() - begin, failed=True)
                    raise
                progress.ended(job[1], time.perf_counter() - begin)

            schedule.run_within(stale, compile_timed, lambda job: unit_memory(job[1]), workers, budget,
                                lambda job, in_use: progress.started(job[1], unit_memory(job[1]), in_use))
            begin = time.perf_counter()
            for ext in self.extensions:
                self.build_extension(ext)
            progress.linked(len(self.extensions), time.perf_counter() - begin)
        finally:
            if out is not sys.stderr:
                out.close()

    def build_extension(self, ext) -> None:
        objects = [str(self.object_of(source)) for source in ext.sources]
        self.compiler.force = True  # linking takes a second; an old .so never survives a reconfiguration
        self.compiler.link_shared_object(
            objects, self.get_ext_fullpath(ext.name), libraries=self.get_libraries(ext),
            library_dirs=ext.library_dirs, runtime_library_dirs=ext.runtime_library_dirs,
            extra_postargs=ext.extra_link_args or [], export_symbols=self.get_export_symbols(ext),
            debug=self.debug, build_temp=self.build_temp, target_lang="c++")

    def configuration(self) -> str:
        """The folder name of this configuration: platform, Python tag and a hash of what the
        objects depend on besides the project's files."""
        compiler = getattr(self.compiler, "compiler_so_cxx", self.compiler.compiler_so)
        try:
            compiler_version = subprocess.run([compiler[0], "--version"], capture_output=True, text=True).stdout
        except OSError:
            compiler_version = ""
        description = {
            "compiler": [compiler, compiler_version], "python": sys.version, "abi": sysconfig.get_config_var("SOABI"),
            "pybind11": version("pybind11"), "libpinocchio": version("libpinocchio"), "eigen": version("cmeel-eigen"),
            "extensions": [[ext.name, ext.define_macros, [a for a in ext.extra_compile_args if not a.startswith("/")]]
                           for ext in self.extensions],
            "optimization": OPTIMIZATION, "unit_flags": UNIT_FLAGS,
        }
        digest = hashlib.sha1(json.dumps(description, sort_keys=True, default=str).encode()).hexdigest()[:12]
        return f"{sysconfig.get_platform()}-{sys.implementation.cache_tag}-{digest}"

    def object_of(self, source: str) -> Path:
        """The object of ``source`` in the kept folder (every extension has the same flags, so a
        source shared by two is compiled once)."""
        return self.object_dir / Path(source).with_suffix(".o")

    def compile_unit(self, ext, source: str) -> None:
        """Compiles ``source`` into :meth:`object_of`, with its dependency file beside it."""
        obj = self.object_of(source)
        obj.parent.mkdir(parents=True, exist_ok=True)
        # Compile into a folder of its own and move the result in place: a build running in the same
        # tree at the same time never links a half-written object.
        with tempfile.TemporaryDirectory(dir=obj.parent) as scratch:
            dep = Path(scratch) / "deps.d"
            [made] = self.compiler.compile([source], output_dir=scratch, macros=ext.define_macros,
                                           include_dirs=ext.include_dirs, debug=self.debug,
                                           extra_postargs=ext.extra_compile_args + OPTIMIZATION.get(source, "").split()
                                           + UNIT_FLAGS.get(source, "").split() + ["-MMD", "-MF", str(dep)])
            os.replace(dep, obj.with_suffix(".d"))
            os.replace(made, obj)

    @staticmethod
    def fresh(source: str, obj: Path) -> bool:
        """``obj`` is newer than ``source`` and every project file its dependency file (beside it) lists."""
        deps = obj.with_suffix(".d")
        if not (obj.is_file() and deps.is_file()):
            return False
        listed = deps.read_text().replace("\\\n", " ").split(":", 1)[-1].split()
        files = {ROOT / source} | {(ROOT / f).resolve() for f in listed if (ROOT / f).resolve().is_relative_to(ROOT)}
        built = obj.stat().st_mtime
        return all(f.is_file() and f.stat().st_mtime <= built for f in files)


def setting(name: str, expected: str) -> float | None:
    """The positive number in environment variable ``name`` (None when unset or empty); a clear
    error naming the variable otherwise."""
    text = os.environ.get(name, "").strip()
    if not text:
        return None
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not value > 0:
        raise SystemExit(f"{name}={text!r}: expected {expected}")
    return value


def unit_memory(source: str) -> float:
    """The peak memory of ``source``'s compile (bytes, :data:`UNIT_MEMORY`)."""
    return UNIT_MEMORY.get(source, max(UNIT_MEMORY.values()))


def available_memory() -> float:
    """Bytes of memory available now (Linux's MemAvailable; elsewhere, enough for every unit at once).
    freefloat.app.atlas.grid has its own reading of it: the build cannot import the package."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024
    except OSError:
        pass
    return sum(UNIT_MEMORY.values())


def extension(name: str, sources: list[str], flags: list[str], **kwargs) -> Pybind11Extension:
    """A C++17 pybind11 extension of ``sources`` with the project's headers (cpp/) and ``flags``."""
    return Pybind11Extension(name, sources, include_dirs=["cpp"], cxx_std=17, extra_compile_args=flags, **kwargs)


# The closed chains' units, in both modules: the bindings and the numerics they call.
CHAINS = ["cpp/bindings/chains.cpp", "cpp/chains/mechanism.cpp", "cpp/chains/inverse.cpp", "cpp/sim/chain_loop.cpp"]
# The dynamics kernel's units (no Pinocchio header): its code and its AVX2 copy (its bindings compile
# in cpp/bindings/sim.cpp's unit).
KERNEL = ["cpp/kernel/kernel.cpp", "cpp/kernel/lanes_avx2.cpp"]
# One set of flags for every translation unit: the closed chains' are shared by both modules.
LINK = {"libraries": ["pinocchio_default"], "library_dirs": [str(PINOCCHIO / "lib")],
        # where the wheel's package sits beside pin's cmeel.prefix; an editable install finds the
        # library because freefloat.dynamics imports pinocchio first
        "runtime_library_dirs": ["$ORIGIN/../../cmeel.prefix/lib"]}

setup(
    ext_modules=[
        extension("freefloat.dynamics._core", ["cpp/bindings/core.cpp", "cpp/gjm/gjm.cpp", "cpp/gjm/models.cpp"] + CHAINS,
                  FLAGS + PINOCCHIO_FLAGS, **LINK),
        extension("freefloat.dynamics._sim",
                  ["cpp/bindings/sim.cpp", "cpp/sim/pin_plant.cpp", "cpp/sim/simulation.cpp", "cpp/sim/closures.cpp",
                   "cpp/sim/loop_detumbling_law.cpp", "cpp/sim/pin_generalized_jacobian.cpp", "cpp/sim/detumbling.cpp"]
                  + CHAINS + KERNEL, FLAGS + PINOCCHIO_FLAGS, **LINK),
    ],
    install_requires=DEPENDENCIES + [f"libpinocchio=={version('libpinocchio')}"],
    cmdclass={"build_ext": BuildExt},
)
