#!/bin/sh
# Set-up for a fresh Debian 12 machine, run as root from the project root:
# installs the compiler, build tools and libraries that are missing, builds
# towstab in ./build and runs the main job on the default example.
#   sh tools/setup.sh [SCENE]
set -eu
cd "$(dirname "$0")/.."

packages="gcc libc6-dev meson ninja-build pkg-config \
  libgsl-dev liblapack-dev libopenblas-dev libarpack2-dev libnlopt-dev \
  libyaml-dev libudunits2-dev libjansson-dev libyajl-dev libsundials-dev libsuitesparse-dev \
  libplplot-dev plplot-driver-cairo libopenmpi-dev openmpi-bin \
  python3 python3-numpy python3-pytest python3-matplotlib \
  chromium"

missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" \
    || missing="$missing $p"
done
if [ -n "$missing" ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "setup: these Debian packages are missing:$missing" >&2
    echo "setup: run this script as root (or install them with apt-get)" >&2
    exit 1
  fi
  echo "setup: installing$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing
fi

if [ -d build ]; then
  meson setup --reconfigure build
else
  meson setup build
fi
ninja -C build

scene="${1:-examples/kamman_ex1_submerged.yaml}"
echo "setup: towstab run $scene"
./build/tools/towstab run "$scene"
