#!/usr/bin/env bash
# Installs the Debian 12 packages vrlcuts needs to build, test and plot.
# Safe to re-run: packages already present are left alone (no apt-get call at all).
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libembree-dev libopenexr-dev libimath-dev
  libtbb-dev libspdlog-dev libfmt-dev libcli11-dev libpugixml-dev libtinyobjloader-dev
  libopenimageio-dev
  libhwy-dev  # render/vrl/vrl_kernel.cpp: portable SIMD with run-time dispatch
  libgtest-dev libgmock-dev
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc
  python3 python3-numpy python3-yaml python3-matplotlib openssl iproute2
  clang libclang-rt-dev llvm  # fuzz/: clang++, libFuzzer and sanitizer runtimes, llvm-symbolizer
  # deploy/smoke.sh: build and run the image with no registry (debootstrap makes the base image);
  # podman-compose runs deploy/compose.yaml, netavark + aardvark-dns resolve its service names
  podman buildah runc fuse-overlayfs uidmap debootstrap podman-compose netavark aardvark-dns iptables
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
