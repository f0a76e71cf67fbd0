#!/usr/bin/env bash
# Installs the system libraries videocal needs: OSMesa/EGL/GL for offscreen VTK rendering,
# what Qt's xcb platform plugin needs to open a window on a desktop, Aravis for GenICam cameras, and iproute2.
# As root it runs apt-get; otherwise it prints the exact command and stops. `--bench` adds the benches' peers.
set -euo pipefail

PACKAGES=(
  libosmesa6 libgl1 libegl1 libglib2.0-0 libfontconfig1 libdbus-1-3
  libxkbcommon0 libxkbcommon-x11-0 libxcb-cursor0 libxcb-icccm4 libxcb-keysyms1
  libxcb-shape0 libxcb-xinerama0 libxcb-randr0 libxcb-render-util0 libxcb-image0
  libxcb-xfixes0 libxcb-xkb1 libx11-xcb1 libxrender1 libxi6
  # GenICam cameras: Aravis and its GObject introspection data; PyGObject is built against these
  libaravis-0.8-0 gir1.2-aravis-0.8 libgirepository1.0-dev libcairo2-dev pkg-config gcc python3-dev
  # arv-tool-0.8, which docs/real-cell.md and docs/connectors.md use to list the cameras and their ids
  aravis-tools-cli
  # a far ROS 2 link (videocal_sim/far_network.py): network namespaces and TUN devices are set up with ip
  iproute2
)
# `--bench`: the peers the benches measure videocal against that come from Debian (ViSP's model-based tracker, built
# by bench/peer_env.py with g++); the tests never need them
if [ "${1:-}" = "--bench" ]; then
  PACKAGES+=(libvisp-mbt-dev nlohmann-json3-dev g++)
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

if ! command -v apt-get >/dev/null 2>&1; then
  echo "videocal: these system libraries are missing and this is not a Debian-like system: ${missing[*]}" >&2
  exit 1
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "videocal needs system libraries. Run this once, then run make again:" >&2
  echo "  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
  exit 1
fi
echo "videocal: installing system libraries: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
