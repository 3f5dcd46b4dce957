#!/bin/sh
# Installs the Debian 12 packages shellmpm needs, only those that are missing.
set -e
PKGS="build-essential cmake pkg-config libeigen3-dev libtbb-dev libopenvdb-dev \
libboost-iostreams-dev libblosc-dev libembree-dev libassimp-dev libosmesa6-dev catch2 \
libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libpng-dev libosd-dev ffmpeg clang-format \
python3-matplotlib"
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
