#!/usr/bin/env bash
# Installs what online_stereo_calibration needs to build, test and run its demo, with apt.
#
# Supported: Debian 12 (bookworm; Debian's own ROS 1 packages, no /opt/ros) and
# Ubuntu 20.04 (focal) + ROS Noetic from packages.ros.org (/opt/ros/noetic).
# Idempotent: when every package is installed it returns at once without touching apt.
# Uses sudo when not run as root. Set OSC_SKIP_DEPS=1 to skip this step entirely
# (e.g. on another distribution where you installed the equivalents yourself).
set -euo pipefail

if [[ "${OSC_SKIP_DEPS:-0}" == "1" ]]; then
  echo "install_deps: OSC_SKIP_DEPS=1, not checking system packages"
  exit 0
fi

# Build tools and libraries with the same name on both systems.
common=(
  cmake g++ make pkg-config
  libeigen3-dev libopencv-dev libyaml-cpp-dev
  libgtest-dev googletest libbenchmark-dev
  python3 python3-matplotlib python3-yaml
)

# Debian 12: ROS 1 as packaged by Debian.
debian_ros=(
  ros-base-dev catkin ros-message-generation python3-catkin-pkg
  libnodeletlib-dev libtf2-ros-dev libtf2-eigen-dev libtf2-geometry-msgs-dev
  libcv-bridge-dev libmessage-filters-dev libimage-transport-dev libdiagnostic-updater-dev
  librosbag-dev librostest-dev python3-rosbag python3-rostest rosbash
  libstd-srvs-dev libnav-msgs-dev libvisualization-msgs-dev
  ros-stereo-image-proc libstereo-image-proc-dev libstereo-msgs-dev
  rviz
)

# Ubuntu 20.04: ROS Noetic from packages.ros.org.
noetic_ros=(
  ros-noetic-ros-base ros-noetic-catkin ros-noetic-message-generation ros-noetic-message-runtime
  ros-noetic-nodelet ros-noetic-tf2-ros ros-noetic-tf2-eigen ros-noetic-tf2-geometry-msgs
  ros-noetic-cv-bridge ros-noetic-message-filters ros-noetic-image-transport
  ros-noetic-diagnostic-updater ros-noetic-rosbag ros-noetic-rostest ros-noetic-rosunit
  ros-noetic-rosbash
  ros-noetic-sensor-msgs ros-noetic-geometry-msgs ros-noetic-nav-msgs ros-noetic-std-srvs
  ros-noetic-visualization-msgs ros-noetic-diagnostic-msgs
  ros-noetic-stereo-image-proc ros-noetic-stereo-msgs
  ros-noetic-rviz
)

if [[ ! -r /etc/os-release ]]; then
  echo "install_deps: /etc/os-release not found; cannot tell the OS" >&2
  exit 1
fi
# shellcheck disable=SC1091
. /etc/os-release
os_id="${ID:-unknown}"
codename="${VERSION_CODENAME:-${UBUNTU_CODENAME:-}}"

noetic=0
case "${os_id}:${codename}" in
  debian:bookworm) packages=("${common[@]}" "${debian_ros[@]}") ;;
  ubuntu:focal) packages=("${common[@]}" "${noetic_ros[@]}"); noetic=1 ;;
  *)
    cat >&2 <<MSG
install_deps: unsupported OS '${PRETTY_NAME:-$os_id}'.
Supported: Debian 12 (bookworm) and Ubuntu 20.04 (focal) with ROS Noetic.
On Debian 12 these packages are needed:
  ${common[*]} ${debian_ros[*]}
On Ubuntu 20.04 + Noetic:
  ${common[*]} ${noetic_ros[*]}
Install the equivalents yourself, then run again with OSC_SKIP_DEPS=1.
MSG
    exit 1
    ;;
esac

# One dpkg-query call for all packages: "name:status" for each package dpkg knows.
installed=" $(dpkg-query -W -f='${Package}:${db:Status-Abbrev}\n' "${packages[@]}" 2>/dev/null |
  awk -F: '$2 ~ /^ii/ {printf "%s ", $1}' || true) "
missing=()
for package in "${packages[@]}"; do
  [[ "$installed" == *" $package "* ]] || missing+=("$package")
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install_deps: all ${#packages[@]} packages installed (${PRETTY_NAME:-$os_id})"
  exit 0
fi

echo "install_deps: installing ${#missing[@]} missing packages: ${missing[*]}"
sudo_cmd=()
if [[ "$(id -u)" -ne 0 ]]; then
  if ! command -v sudo >/dev/null 2>&1; then
    echo "install_deps: not root and sudo is not installed; install as root: ${missing[*]}" >&2
    exit 1
  fi
  sudo_cmd=(sudo)
fi
apt_get() {
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get "$@"
}
apt_install() {
  apt_get install -y --no-install-recommends "$@"
}

apt_get update

# Ubuntu 20.04: add the ROS 1 apt source (packages.ros.org) if apt does not know Noetic yet.
has_candidate() {
  local candidate
  candidate="$(apt-cache policy "$1" 2>/dev/null | awk '/Candidate:/ {print $2}')"
  [[ -n "$candidate" && "$candidate" != "(none)" ]]
}
if [[ $noetic -eq 1 ]] && ! has_candidate ros-noetic-ros-base; then
  echo "install_deps: adding the ROS 1 apt source (ros-infrastructure/ros-apt-source)"
  apt_install ca-certificates curl
  release_api="https://api.github.com/repos/ros-infrastructure/ros-apt-source/releases/latest"
  version="$(curl -fsSL "$release_api" | sed -n 's/.*"tag_name": *"\([^"]*\)".*/\1/p' | head -n 1)"
  if [[ -z "$version" ]]; then
    echo "install_deps: could not read the latest ros-apt-source release from $release_api" >&2
    exit 1
  fi
  deb="$(mktemp --suffix=.deb)"
  trap 'rm -f "$deb"' EXIT
  curl -fsSL -o "$deb" \
    "https://github.com/ros-infrastructure/ros-apt-source/releases/download/${version}/ros-apt-source_${version}.${codename}_all.deb"
  chmod 644 "$deb"
  apt_install "$deb"
  apt_get update
fi

apt_install "${missing[@]}"
echo "install_deps: done"
