"""`pip install .`: the package python/tessera plus its extension _tessera,
built by the repository's CMake build (target tessera_python) into
$TESSERA_BUILD_DIR or build/, then copied into the wheel. An extension
already built there is reused. See docs/python.md."""
import glob
import os
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("TESSERA_BUILD_DIR") or os.path.join(HERE, "build")
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = os.path.join(build, "python", "tessera", "_tessera" + suffix)
        if not os.path.exists(built):
            subprocess.check_call(
                ["cmake", "-S", HERE, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                 "-DTESSERA_PYTHON=ON", f"-DPython_EXECUTABLE={sys.executable}"])
            subprocess.check_call(
                ["cmake", "--build", build, "--target", "tessera_python",
                 f"-j{os.cpu_count() or 2}"])
        found = glob.glob(built)
        if not found:
            raise RuntimeError(f"tessera: the CMake build did not produce {built}")
        dest = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        shutil.copy2(found[0], dest)


setup(
    name="tessera",
    version="0.1.0",
    description="Volume rendering for GPUs that lack something, headless through EGL",
    packages=["tessera"],
    package_dir={"": "python"},
    package_data={"tessera": ["*.pyi", "py.typed"]},
    ext_modules=[Extension("tessera._tessera", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.9",
    install_requires=["numpy"],
    zip_safe=False,
    options={"build": {"build_base": os.path.join("build", "setuptools")}},
)
