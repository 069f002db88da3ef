#!/usr/bin/env bash
# Installs the Debian packages dmc needs, only those missing. Idempotent; run as root or with sudo.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libdraco-dev libopenmesh-dev libzstd-dev libgtest-dev libgmock-dev
  libbenchmark-dev libmeshoptimizer-dev libsuitesparse-dev libtbb-dev libcli11-dev libfmt-dev nlohmann-json3-dev libxxhash-dev
  libopenblas-dev  # the opt-in CHOLMOD backend's BLAS (-DDMC_WITH_CHOLMOD=ON; the sanitised CI stage)
  libhwy-dev       # Google Highway: the SIMD variants of frame synthesis (dmc/simd.h)
  libtinygltf-dev libspectra-dev            # glTF import/export; eigensolvers for spectral methods
  gltfpack                                  # meshopt-compressed GLB inputs for the glTF tests
  pybind11-dev python3-dev python3-numpy python3-scipy  # the Python module and its tests
  python3-pip python3-setuptools python3-wheel python3-venv  # the wheel, built and tested offline
  python3-distributed                       # python -m dmc.batch (Dask) and its test
  clang-14 libclang-rt-14-dev               # libFuzzer and the sanitizer runs
  clang-format-14 ccache                    # tools/test.sh's formatting check; compiler cache
  python3-clang-14                          # libclang's parser for tools/check-sizes.py
  chromium                                  # the viewer's headless browser test (node and npm ship with the machine)
  emscripten node-acorn                     # the WebAssembly decoder (web/build.sh; acorn for emcc's JS optimiser)
  dpkg-dev debootstrap                      # the .deb: dpkg-shlibdeps for its dependencies, a clean Debian 12 root to test it
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
