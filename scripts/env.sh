# shellcheck shell=bash
# ipfric runtime environment. Source it (./ipfric does):   source scripts/env.sh
# Works under `set -euo pipefail`, and sourcing it twice gives the same environment.
#
# - DDS stays on loopback: ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, always (overrides the
#   caller), and the variables that could add peers or transports outside loopback are unset.
# - RMW_IMPLEMENTATION=rmw_fastrtps_cpp (the only RMW the wheels ship).
# - .venv/bin first on PATH; AMENT_PREFIX_PATH and CMAKE_PREFIX_PATH = .venv (the ROS wheels
#   install their share/, lib/ and ament index there). A ROS sourced in the caller's shell
#   (/opt/ros/..., another workspace) is dropped: PYTHONPATH, COLCON_PREFIX_PATH are reset.
# - LD_LIBRARY_PATH = .venv/lib + the wheels' ros_*.libs directories, i.e. exactly what the
#   ros-wheels-bootstrapper .pth hook would set, and _ROS_WHEELS_BOOTSTRAP_COMPLETE=1, so that
#   hook does not re-execute every Python process (saves ~0.1 s per process).
# - Then ros2_ws/install/local_setup.bash (colcon) if the workspace is built: it prepends
#   install/<pkg>/lib/python3.11/site-packages to PYTHONPATH (the generated ipfric_msgs
#   Python package), install/<pkg>/lib to LD_LIBRARY_PATH (libipfric_msgs__rosidl_*.so, the
#   C type support that rclpy loads) and install/<pkg> to AMENT_PREFIX_PATH.

_ipfric_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)"
_ipfric_venv="$_ipfric_root/.venv"
export IPFRIC_ROOT="$_ipfric_root"

# ---- DDS: loopback only
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
unset ROS_STATIC_PEERS ROS_LOCALHOST_ONLY ROS_DISCOVERY_SERVER ROS_SUPER_CLIENT \
      FASTRTPS_DEFAULT_PROFILES_FILE FASTDDS_DEFAULT_PROFILES_FILE FASTDDS_ENVIRONMENT_FILE \
      RMW_FASTRTPS_USE_QOS_FROM_XML
export RMW_IMPLEMENTATION=rmw_fastrtps_cpp

# ---- numerics: one BLAS thread, so that a fit takes the same path on every run (sums in one order)
export OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1

# ---- Python: the project's venv
if [ ! -x "$_ipfric_venv/bin/python" ]; then
  echo "[env] warning: $_ipfric_venv is missing; run scripts/setup.sh" >&2
fi
export VIRTUAL_ENV="$_ipfric_venv"
unset PYTHONHOME PYTHONPATH CONDA_PREFIX
case ":${PATH:-}:" in
  *":$_ipfric_venv/bin:"*) ;;
  *) export PATH="$_ipfric_venv/bin${PATH:+:$PATH}" ;;
esac

# ---- ROS 2 from the wheels
export AMENT_PREFIX_PATH="$_ipfric_venv"
export CMAKE_PREFIX_PATH="$_ipfric_venv"
unset COLCON_PREFIX_PATH COLCON_CURRENT_PREFIX ROS_PACKAGE_PATH
_ipfric_ld="$_ipfric_venv/lib"
for _ipfric_d in "$_ipfric_venv"/lib/python3.11/site-packages/ros_*.libs; do
  if [ -d "$_ipfric_d" ]; then _ipfric_ld="$_ipfric_ld:$_ipfric_d"; fi
done
export LD_LIBRARY_PATH="$_ipfric_ld"
export _ROS_WHEELS_BOOTSTRAP_COMPLETE=1

# ---- the built workspace (ipfric_msgs, ipfric_core, later ipfric_sim, ipfric_controller)
if [ -f "$_ipfric_root/ros2_ws/install/local_setup.bash" ]; then
  # colcon's scripts compute the environment with this interpreter
  COLCON_PYTHON_EXECUTABLE="$_ipfric_venv/bin/python3"
  export COLCON_PYTHON_EXECUTABLE
  # colcon's and ament's scripts are not written for `set -eu`: relax both while sourcing
  _ipfric_opts="$-"
  set +eu
  # shellcheck disable=SC1091
  . "$_ipfric_root/ros2_ws/install/local_setup.bash"
  _ipfric_rc=$?
  case "$_ipfric_opts" in *e*) set -e ;; esac
  case "$_ipfric_opts" in *u*) set -u ;; esac
  if [ "$_ipfric_rc" != 0 ]; then
    echo "[env] warning: sourcing ros2_ws/install/local_setup.bash failed ($_ipfric_rc)" >&2
  fi
fi

unset _ipfric_root _ipfric_venv _ipfric_ld _ipfric_d _ipfric_opts _ipfric_rc
