#!/usr/bin/env bash
# Installs every Debian package spar's build, tests and benchmarks need. Idempotent: safe to run
# twice; does nothing but a quick check when everything is already there.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev
  libnlopt-cxx-dev libsuitesparse-dev
  libfcl-dev                       # geometry/: collision and distance between posed meshes
  liburdfdom-dev libkdl-parser-dev # kinematics/: URDF robots (KDL is also the IK peer in bench/)
  libboost-math-dev                # planner/: normal quantile, Wilson interval
  libcli11-dev nlohmann-json3-dev libyaml-cpp-dev libfmt-dev
  libgtest-dev libgmock-dev librapidcheck-dev libbenchmark-dev
  libmpfi-dev                      # tests only: rigorous oracle for the Interval kernels
  libginac-dev liborocos-kdl-dev gappa  # benchmarks only: peers
  python3 python3-sympy python3-numpy  # benchmarks only: SymPy peer
  chromium                         # tests only: the HTML report in a real browser
  clang libclang-rt-14-dev llvm    # scripts/hunt.sh: ASan + UBSan build, libFuzzer, symbolizer
  pybind11-dev python3-pybind11 python3-pytest python3-distributed python3-dask  # python/
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
