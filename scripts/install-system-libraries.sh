#!/usr/bin/env bash
# gmsh's Python wheel links against a few X11/OpenGL libraries that minimal Linux images lack.
# Install them from Debian/Ubuntu packages when they are missing (needs root or sudo).
set -euo pipefail
needed=(libGLU.so.1 libXrender.so.1 libXcursor.so.1 libXft.so.2 libXinerama.so.1 libgomp.so.1 libX11.so.6)
missing=0
for lib in "${needed[@]}"; do
  ldconfig -p 2>/dev/null | grep -q "$lib" || missing=1
done
if [ "$missing" = 0 ]; then
  exit 0
fi
SUDO=""
[ "$(id -u)" = 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq libglu1-mesa libxrender1 libxcursor1 libxft2 libxinerama1 libgomp1 libx11-6 >/dev/null
