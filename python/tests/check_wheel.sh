#!/usr/bin/env bash
# ctest python.wheel: builds the wheel offline with Debian's pip, setuptools and wheel (the
# extension from BUILD_DIR, as DMC_CMAKE_BUILD_DIR tells python/setup.py), installs it into a
# fresh virtual environment (--system-site-packages, for NumPy and SciPy), and runs the Python
# test suite there, from outside the source and build trees, against the installed package.
# Usage: check_wheel.sh PYTHON BUILD_DIR [DMC_CLI]
set -euo pipefail
python="$1"
build="$(cd "$2" && pwd)"
cli="${3:-}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "check-wheel: $*" >&2; exit 1; }

DMC_CMAKE_BUILD_DIR="$build" "$python" -m pip wheel --no-build-isolation --no-deps --no-index \
  --quiet "$here/.." -w "$work/wheel" || fail "pip wheel failed"
wheel=$(ls "$work"/wheel/dmc-*.whl)
echo "check-wheel: $(basename "$wheel")"
"$python" -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install --no-index --no-deps --quiet "$wheel" || fail "pip install failed"
cd "$work"
env -u PYTHONPATH "$work/venv/bin/python" -c "
import dmc, os, sys
assert dmc.__file__.startswith('$work/venv/'), dmc.__file__
assert os.path.exists(os.path.join(os.path.dirname(dmc.__file__), 'LICENSE'))
print('check-wheel: dmc', dmc.__version__, 'from', os.path.dirname(dmc.__file__))
"
# The suite, run from the scratch directory: its own directory (for support.py) is on the path, the
# source package python/dmc is not, so `import dmc` is the installed wheel.
env -u PYTHONPATH DMC_CLI="$cli" PYTHONDONTWRITEBYTECODE=1 \
  "$work/venv/bin/python" -m unittest discover -s "$here" -p 'test_*.py' 2>"$work/unittest.log" ||
  { tail -30 "$work/unittest.log" >&2; fail "the tests failed against the installed wheel"; }
tail -3 "$work/unittest.log"
echo "check-wheel: the wheel installs into a fresh virtual environment and its tests pass there"
