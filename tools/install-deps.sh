#!/bin/sh
# Installs the Debian 12 packages shellmpm needs, only those that are missing.
set -e
PKGS="build-essential cmake pkg-config libeigen3-dev libtbb-dev libopenvdb-dev \
libboost-iostreams-dev libblosc-dev libembree-dev libassimp-dev libosmesa6-dev catch2 \
libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libpng-dev libosd-dev ffmpeg clang-format \
python3-matplotlib libmumps-seq-5.5 libmumps-headers-dev libopenblas0"
MISSING=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || MISSING="$MISSING $p"
done
if [ -n "$MISSING" ]; then
  echo "installing:$MISSING"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $MISSING
fi
# The farm's tests (tests/farm): a single-node Slurm (slurm-wlm, munge; started by
# tools/farm/slurm-local.sh) and headless Chromium for the review page. Without
# recommends: the daemons are started by hand, not as services.
FARM_PKGS="slurm-wlm munge chromium"
MISSING=""
for p in $FARM_PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || MISSING="$MISSING $p"
done
if [ -n "$MISSING" ]; then
  echo "installing:$MISSING"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $MISSING
fi
