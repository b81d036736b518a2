#!/usr/bin/env bash
# Installs the Debian 12 packages slamrig builds and tests with, and only those that are missing.
# Idempotent: a second run installs nothing and makes no network request.
#
#   scripts/install_deps.sh          everything the test suite needs (CI)
#   scripts/install_deps.sh --main   only what `slamrig` and `import slamrig` need to build and run
#                                    (and to configure: GoogleTest and Google Benchmark are small)
set -euo pipefail

packages=(
  build-essential cmake pkg-config ccache
  libbox2d-dev libeigen3-dev libopencv-dev libmujoco-dev libyaml-cpp-dev libceres-dev
  libgtest-dev libgmock-dev libbenchmark-dev libsqlite3-dev zlib1g-dev libnanoflann-dev
  libspectra-dev
  libzstd-dev liblz4-dev
  libboost-dev nlohmann-json3-dev # `slamrig run --live`: Boost.Beast/Asio, the protocol's JSON
  libegl-dev libegl-mesa0 libgl1-mesa-dri
  pybind11-dev python3-dev python3-numpy
)
main_only=0
if [[ ${1:-} == --main ]]; then
  main_only=1
elif (($# > 0)); then
  echo "install_deps: unknown argument '$1'; expected nothing or --main" >&2
  exit 2
fi
if ((!main_only)); then
  packages+=(
    clang-format clang libclang-rt-14-dev # formatting check, sanitizer and fuzz build
    slurm-wlm munge                       # the local Slurm of the sweep test
    procps universal-ctags python3-pytest # process checks, function lengths, Python tests
  )
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# Node.js and npm (the ROS 2 bag cross-check runs Foxglove's readers): Debian's nodejs and npm,
# unless a Node.js with its npm is already installed (a nodejs package that bundles npm conflicts
# with Debian's npm).
if ((!main_only)) && { ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; }; then
  missing+=(nodejs npm)
fi

if ((${#missing[@]} == 0)); then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
