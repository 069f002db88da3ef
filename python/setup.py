"""Builds the dmc wheel: the extension dmc._dmc is compiled by the repository's CMake build (the
same target, dmc_python, that `cmake -DDMC_BUILD_PYTHON=ON` builds), for the interpreter running
this script, and copied into the package.

Environment:
  DMC_CMAKE_BUILD_DIR  an existing CMake build directory of this repository (configured with
                       DMC_BUILD_PYTHON=ON for this interpreter) to build the module in, instead
                       of a fresh Release build under setuptools' build_temp (which compiles the
                       whole library: minutes);
  DMC_CMAKE_ARGS       further arguments for the fresh configuration (e.g. -DDMC_WITH_CHOLMOD=ON);
  DMC_BUILD_JOBS       parallel build jobs (default: the CPU count).
"""

import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def version():
    with open(os.path.join(ROOT, "codec", "include", "dmc", "version.h"), encoding="utf-8") as header:
        text = header.read()
    parts = [re.search(rf"#define DMC_VERSION_{part} (\d+)", text).group(1)
             for part in ("MAJOR", "MINOR", "PATCH")]
    return ".".join(parts)


class CMakeBuild(build_ext):
    def build_extension(self, extension):
        build_dir = os.environ.get("DMC_CMAKE_BUILD_DIR")
        if not build_dir:
            build_dir = os.path.abspath(os.path.join(self.build_temp, "cmake"))
            configure = ["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                         "-DDMC_BUILD_PYTHON=ON", "-DDMC_BUILD_TESTS=OFF",
                         "-DDMC_BUILD_TOOLS=OFF", f"-DPython_EXECUTABLE={sys.executable}"]
            configure += os.environ.get("DMC_CMAKE_ARGS", "").split()
            subprocess.run(configure, check=True)
        jobs = os.environ.get("DMC_BUILD_JOBS", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "--build", build_dir, "--target", "dmc_python", "-j", jobs],
                       check=True)
        built = glob.glob(os.path.join(build_dir, "python", "dmc", "_dmc*.so"))
        if len(built) != 1:
            raise RuntimeError(f"expected one dmc/_dmc*.so in {build_dir}/python, found {built}")
        target = self.get_ext_fullpath(extension.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built[0], target)
        # The licence travels with the package (licenses/README.md lists what the module holds).
        for name in ("LICENSE", "NOTICE"):
            shutil.copyfile(os.path.join(ROOT, name), os.path.join(os.path.dirname(target), name))


setup(
    version=version(),
    ext_modules=[Extension("dmc._dmc", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
)
