#!/usr/bin/env bash
# Installs every Debian package stereograsp needs (only those missing), then configures and
# builds. Safe to run again and again.
#
#   scripts/bootstrap.sh                 install what is missing, build into build/
#   scripts/bootstrap.sh --no-build      install only
#   scripts/bootstrap.sh --build-dir DIR build elsewhere
#   scripts/bootstrap.sh --debug         Debug build instead of Release
#   scripts/bootstrap.sh --with-clang    also clang and its runtimes (scripts/fuzz.sh)
set -euo pipefail
cd "$(dirname "$0")/.."

build=1
build_dir=build
build_type=Release
with_clang=0
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) build=0 ;;
    --build-dir) build_dir="$2"; shift ;;
    --debug) build_type=Debug ;;
    --with-clang) with_clang=1 ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bootstrap.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

# Why each package is here: docs/architecture.md, "Dependencies".
packages=(
  cmake g++ make                                   # the build
  liblcm-dev liblcm-bin liblcm-java               # LCM: library, lcm-gen/logger/logplayer, lcm.jar
  default-jdk-headless default-jre libjchart2d-java  # the types jar, lcm-spy and its charts
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev  # config, flags, logging
  libeigen3-dev                                    # linear algebra
  libhwy-dev                                       # Highway: SIMD kernels, dispatched at run time
  libopencv-dev                                    # images, video files, calibration
  opencv-doc                                       # real photographs and video (real-scene tests)
  libturbojpeg0-dev                                # a JPEG's size from its header, before decoding
  libjpeg62-turbo-dev                              # libjpeg API: decode only a search window
  libgtest-dev libgmock-dev libbenchmark-dev       # tests and benchmarks
  nlohmann-json3-dev                               # sg-report's report.json (and its tests)
  libsodium-dev pkg-config                         # signed commands (auth/: HMAC, the lab key)
  gnuplot-nox                                      # sg-report's PNG figures (pngcairo terminal)
  iproute2 util-linux                              # ip and unshare for scripts/multicast.sh
  python3                                          # scripts/*.py and their tests
  rt-tests                                         # cyclictest: scripts/machine_latency.py
  iptables faketime                                # fault injection: packet loss, clock skew
  openssh-client openssh-server                    # sg-lab: processes on other hosts; its tests'
                                                   # hosts (network namespaces with an sshd)
)
# Only for scripts/fuzz.sh: clang with libFuzzer, ASan and UBSan runtimes (libclang-rt-dev),
# llvm-symbolizer (llvm) for file:line in sanitizer reports, and lld, the sanitized build's linker.
[ "$with_clang" -eq 0 ] || packages+=(clang libclang-rt-dev llvm lld)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "bootstrap: installing ${missing[*]}"
  if [ "$(id -u)" -eq 0 ]; then
    sudo=()
  elif command -v sudo >/dev/null; then
    sudo=(sudo)
  else
    echo "bootstrap: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  echo "bootstrap: packages installed"
fi

[ "$build" -eq 1 ] || exit 0

cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="$build_type" >/dev/null
cmake --build "$build_dir" -j "$(nproc)"
echo "bootstrap: built into $build_dir/ (programs in $build_dir/bin)"
