#!/usr/bin/env bash
# Install the Debian packages some tests use, when missing and when we can.
set -u
need=()
command -v check_urdf >/dev/null 2>&1 || need+=(liburdfdom-tools)
command -v chromium >/dev/null 2>&1 || need+=(chromium)
command -v chromedriver >/dev/null 2>&1 || need+=(chromium-driver)
command -v bwrap >/dev/null 2>&1 || need+=(bubblewrap)  # --trust-xacro sandbox (xacro_jail)
command -v ign >/dev/null 2>&1 || need+=(libsdformat-dev ignition-tools)  # `ign sdf -k`: Gazebo's URDF parser (tests)
# camera sensors: MuJoCo's offscreen rendering through EGL on Mesa's CPU renderer (llvmpipe)
ldconfig -p 2>/dev/null | grep -q 'libEGL_mesa\.so' || need+=(libegl1 libegl-mesa0 libgl1-mesa-dri)
[ ${#need[@]} -eq 0 ] && exit 0
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
  echo "sysdeps: cannot install ${need[*]} (need root and apt-get); the tests using them will skip" >&2
  exit 0
fi
echo "sysdeps: installing ${need[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq >/dev/null 2>&1 || true
apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null 2>&1 \
  || echo "sysdeps: apt-get install ${need[*]} failed; the tests using them will skip" >&2
exit 0
