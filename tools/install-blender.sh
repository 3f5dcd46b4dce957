#!/bin/sh
# Installs Debian 12's Blender (3.4.1, about 1 GB with its dependencies) for the Blender
# loader (tools/blender/shellmpm_import.py) and its slow test. The default suite does not
# need it: tools/install-deps.sh leaves it out on purpose.
set -e
if dpkg-query -W -f='${Status}' blender 2>/dev/null | grep -q "install ok installed"; then
  echo "blender is installed: $(command -v blender)"
  exit 0
fi
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq blender
blender --version | head -1
