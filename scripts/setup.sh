#!/usr/bin/env bash
# ipfric: the one setup path for a fresh Debian 12 machine. Idempotent: a second run only checks.
#
#   bash scripts/setup.sh            # set up / bring up to date, report every step
#   bash scripts/setup.sh --quiet    # print only when something has to be done (used by ./ipfric)
#
# Steps (each skipped when already done):
#   a) apt packages: cmake, g++, make (+ python3, python3-dev, python3-venv when the system
#      Python is the one used); apt-get runs only when one of them is missing
#   b) .venv at the repo root with `python3` 3.11, pip install -r requirements.txt
#      (stamp: sha256 of requirements.txt in .venv/.ipfric-requirements.sha256)
#   c) editable install of src/ipfric_core into .venv (importable without ROS)
#   d) fix of the CMake files exported by the ROS wheels (.venv/share/*/cmake/): they hard-code
#      the wheel builder's Python and NumPy include directories
#   e) colcon build --symlink-install of src/ into ros2_ws/ (stamp: hash of the src/ tree,
#      in ros2_ws/install/.ipfric-src.sha256)
#
# Progress goes to stderr, so that `./ipfric <cmd>` keeps its stdout clean.
set -euo pipefail

QUIET=0
case "${1:-}" in
  --quiet|-q) QUIET=1 ;;
  "") ;;
  -h|--help) sed -n '2,18p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "[setup] unknown argument: $1 (use --quiet)" >&2; exit 2 ;;
esac

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)"
VENV="$ROOT/.venv"
WS="$ROOT/ros2_ws"
REQ="$ROOT/requirements.txt"
REQ_STAMP="$VENV/.ipfric-requirements.sha256"
CORE_STAMP="$VENV/.ipfric-core-editable.sha256"
BUILD_STAMP="$WS/install/.ipfric-src.sha256"
LOCK="$WS/.setup.lock"
BUILD_LOG="$WS/log/setup-build.log"
# The exported CMake files of the wheels name these directories of the wheel builder.
BAD_PY_INC="/opt/python/cp311-cp311/include/python3.11"
BAD_NP_INC="/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include"

DID=0
say()  { DID=1; echo "[setup] $*" >&2; }
info() { [ "$QUIET" = 1 ] || echo "[setup] $*" >&2; }
die()  { echo "[setup] ERROR: $*" >&2; exit 1; }
trap 'rc=$?; [ $rc -eq 0 ] || echo "[setup] FAILED (exit $rc) at line $LINENO: $BASH_COMMAND" >&2' ERR

# ---- do not depend on whatever the calling shell has set (a sourced ROS, another venv, ...)
unset PYTHONPATH PYTHONHOME PYTHONSTARTUP PYTHONUSERBASE VIRTUAL_ENV CONDA_PREFIX \
      AMENT_PREFIX_PATH CMAKE_PREFIX_PATH COLCON_PREFIX_PATH COLCON_CURRENT_PREFIX \
      COLCON_DEFAULTS_FILE COLCON_LOG_PATH LD_LIBRARY_PATH LD_PRELOAD ROS_DISTRO ROS_VERSION \
      ROS_PYTHON_VERSION ROS_PACKAGE_PATH PIP_USER PIP_REQUIRE_VIRTUALENV PIP_TARGET PIP_PREFIX \
      CC CXX CFLAGS CXXFLAGS LDFLAGS CMAKE_GENERATOR CMAKE_BUILD_TYPE 2>/dev/null || true
# `python3` is taken from PATH as found (it only chooses the interpreter of a new .venv);
# the system directories are appended so that a bare PATH still works.
export PATH="${PATH:+$PATH:}/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin"
export LC_ALL=C.UTF-8 LANG=C.UTF-8
export COLCON_HOME="$WS/.colcon"          # ignore a developer's ~/.colcon/defaults.yaml
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST   # never let DDS leave loopback (nothing here talks DDS)
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_INPUT=1
# The ROS wheels re-exec every Python process once to set LD_LIBRARY_PATH; setup's own
# helper calls need no ROS library, so skip that.
PYENV_NOBOOT=(env _ROS_WHEELS_BOOTSTRAP_COMPLETE=1)

sha256_of() { sha256sum "$1" | cut -d' ' -f1; }

[ -f "$REQ" ] || die "missing $REQ"
mkdir -p "$WS"
# Two ./ipfric started at once must not both build: serialize on a lock.
exec 9>"$LOCK"
if ! flock -n 9; then
  say "another setup is running; waiting for it"
  flock 9
fi

# ---------------------------------------------------------------- (a) system packages
pick_python() {
  local c
  for c in python3 python3.11 /usr/bin/python3.11; do
    if command -v "$c" >/dev/null 2>&1 \
       && "$c" -c 'import sys; sys.exit(0 if sys.version_info[:2] == (3, 11) else 1)' >/dev/null 2>&1; then
      command -v "$c"; return 0
    fi
  done
  return 1
}

# A usable .venv prints its base interpreter's prefix; otherwise choose the interpreter of a new one.
venv_base() {
  [ -x "$VENV/bin/python" ] && "${PYENV_NOBOOT[@]}" "$VENV/bin/python" -c \
    'import sys; assert sys.version_info[:2] == (3, 11) and sys.prefix != sys.base_prefix; print(sys.base_prefix)' \
    2>/dev/null
}
BASE="$(venv_base || true)"
PY=""
if [ -z "$BASE" ]; then
  PY="$(pick_python || true)"
  [ -z "$PY" ] || BASE="$("$PY" -c 'import sys; print(sys.base_prefix)')"
fi
APT_PKGS=(cmake g++ make)
if [ -z "$BASE" ]; then
  APT_PKGS+=(python3 python3-dev python3-venv)          # Debian 12's python3 is 3.11
elif [ "$BASE" = /usr ]; then
  APT_PKGS+=(python3-dev python3-venv)                   # headers + ensurepip of the system Python
fi
missing=()
for p in "${APT_PKGS[@]}"; do
  [ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)" = "install ok installed" ] || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  say "installing apt packages: ${missing[*]}"
  command -v apt-get >/dev/null || die "apt-get not found: install ${missing[*]} by hand (Debian 12 expected)"
  SUDO=()
  if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null || die "not root and no sudo: install ${missing[*]} by hand"
    SUDO=(sudo)
  fi
  "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq >&2 \
    || die "apt-get update failed"
  "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >&2 || die "apt-get install ${missing[*]} failed"
else
  info "apt packages present: ${APT_PKGS[*]}"
fi

# ---------------------------------------------------------------- (b) .venv + requirements
if [ -z "$(venv_base || true)" ]; then
  [ -n "$PY" ] || PY="$(pick_python || true)"
  [ -n "$PY" ] || die "no Python 3.11 interpreter found (the ROS 2 Kilted wheels are cp311 only)"
  [ ! -e "$VENV" ] || { say "existing .venv is unusable; recreating it"; rm -rf "$VENV"; }
  say "creating .venv with $PY ($("$PY" -c 'import sys; print(sys.version.split()[0])'))"
  "$PY" -m venv "$VENV" || die "python3 -m venv failed (on the system Python: apt-get install python3-venv)"
fi
VPY="$VENV/bin/python"
req_hash="$(sha256_of "$REQ")"
if [ "$(cat "$REQ_STAMP" 2>/dev/null || true)" != "$req_hash" ]; then
  say "pip install -r requirements.txt (a few minutes on a cold cache; log: .venv/pip-install.log)"
  rm -f "$REQ_STAMP"
  t0=$SECONDS
  if ! "${PYENV_NOBOOT[@]}" "$VPY" -m pip install -r "$REQ" >"$VENV/pip-install.log" 2>&1; then
    grep -v "is ignored: it is neither a file nor a directory" "$VENV/pip-install.log" | tail -n 40 >&2
    die "pip install -r requirements.txt failed (full log: .venv/pip-install.log)"
  fi
  echo "$req_hash" >"$REQ_STAMP"
  say "requirements installed in $((SECONDS - t0)) s"
else
  info "requirements up to date (.venv)"
fi

# ---------------------------------------------------------------- (c) editable src/ipfric_core
# src/ipfric_core has a setup.py and no pyproject.toml, so pip does a `setup.py develop`
# install: an ipfric-core.egg-link plus a path entry in easy-install.pth (compat mode, should
# pip use PEP 660): modules and packages added later are importable without reinstalling.
CORE="$ROOT/src/ipfric_core"
if [ -f "$CORE/setup.py" ]; then
  core_hash="$(cat "$CORE/setup.py" "$CORE/setup.cfg" "$CORE/package.xml" "$REQ_STAMP" 2>/dev/null \
               | sha256sum | cut -d' ' -f1)"
  if [ "$(cat "$CORE_STAMP" 2>/dev/null || true)" != "$core_hash" ] \
     || ! compgen -G "$VENV/lib/python3.11/site-packages/*ipfric?core*" >/dev/null; then
    say "pip install -e src/ipfric_core (editable)"
    rm -f "$CORE_STAMP"
    if ! "${PYENV_NOBOOT[@]}" "$VPY" -m pip install --no-deps --no-build-isolation \
         --config-settings editable_mode=compat -e "$CORE" >"$VENV/pip-core.log" 2>&1; then
      grep -v "is ignored: it is neither a file nor a directory" "$VENV/pip-core.log" | tail -n 40 >&2
      die "editable install of src/ipfric_core failed (log: .venv/pip-core.log)"
    fi
    echo "$core_hash" >"$CORE_STAMP"
  else
    info "ipfric_core editable install up to date"
  fi
else
  say "warning: src/ipfric_core/setup.py not found; skipping its editable install"
fi

# ---------------------------------------------------------------- (d) CMake path fix
include_dirs() {
  PY_INC="$("${PYENV_NOBOOT[@]}" "$VPY" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
  NP_INC="$("${PYENV_NOBOOT[@]}" "$VPY" -c 'import numpy; print(numpy.get_include())')" \
    || die "numpy is not importable in .venv"
  [ -f "$PY_INC/Python.h" ] || die "Python.h not found in $PY_INC (system Python: apt-get install python3-dev)"
  [ -d "$NP_INC" ] || die "numpy include directory $NP_INC does not exist"
}
mapfile -t bad < <(grep -rlF -e "$BAD_PY_INC" -e "$BAD_NP_INC" "$VENV"/share/*/cmake/ 2>/dev/null || true)
if [ ${#bad[@]} -gt 0 ]; then
  include_dirs
  say "fixing builder paths in ${#bad[@]} exported CMake file(s) of the ROS wheels"
  for f in "${bad[@]}"; do
    # '|' cannot occur in either path; the numpy path is replaced first (it is the longer one)
    sed -i -e "s|$BAD_NP_INC|$NP_INC|g" -e "s|$BAD_PY_INC|$PY_INC|g" "$f"
  done
  if grep -rqF -e "$BAD_PY_INC" -e "$BAD_NP_INC" "$VENV"/share/*/cmake/; then
    die "CMake path fix left builder paths behind"
  fi
else
  info "CMake files of the wheels already fixed"
fi

# ---------------------------------------------------------------- (e) colcon build of ros2_ws
src_hash() {
  # paths + contents of every file under src/ (the symlinked config/ followed; build by-products
  # excluded), plus what the build depends on outside src/: the venv's requirements and this recipe
  {
    (cd "$ROOT" && find -L src \( -name __pycache__ -o -name '*.egg-info' -o -name .pytest_cache \) -prune \
        -o \( -type f -o -type l \) ! -name '*.pyc' -print0 | LC_ALL=C sort -z | xargs -0 -r sha256sum)
    echo "requirements $req_hash"
    echo "python $VPY"
    echo "recipe 1 colcon build --symlink-install --base-paths ../src"
  } | sha256sum | cut -d' ' -f1
}
cur_hash="$(src_hash)"
if [ "$(cat "$BUILD_STAMP" 2>/dev/null || true)" != "$cur_hash" ]; then
  say "colcon build of ros2_ws (src/ changed or first build)"
  rm -f "$BUILD_STAMP"
  mkdir -p "$WS/log"
  include_dirs   # fails early and clearly when Python.h or numpy's headers are missing
  t0=$SECONDS
  if ! (
    cd "$WS"
    export VIRTUAL_ENV="$VENV" PATH="$VENV/bin:$PATH"
    export CMAKE_PREFIX_PATH="$VENV" AMENT_PREFIX_PATH="$VENV"
    "$VENV/bin/colcon" build --symlink-install --base-paths ../src \
      --event-handlers console_cohesion+ status- desktop_notification- \
      --cmake-args -DPython3_EXECUTABLE="$VPY" -DBUILD_TESTING=OFF \
      >"$BUILD_LOG" 2>&1
  ); then
    tail -n 60 "$BUILD_LOG" >&2
    die "colcon build failed (full output: ros2_ws/log/setup-build.log)"
  fi
  echo "$cur_hash" >"$BUILD_STAMP"
  say "workspace built in $((SECONDS - t0)) s: $(find "$WS/install" -mindepth 1 -maxdepth 1 -type d -printf '%f\n' | sort | tr '\n' ' ')"
else
  info "ros2_ws up to date with src/"
fi

if [ "$DID" = 1 ]; then say "done"; else info "up to date"; fi
