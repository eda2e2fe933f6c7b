# Sourced by the Python suites (python/run-tests.sh, tests/conformance/run.sh, tests/system/web/run.sh):
# what they share before pytest. python_suite_setup LABEL [BUILD_DIR] [PYTEST_ARGS...] takes the
# build folder (the first argument when it is not an option; default the repository's build/),
# checks the build's binaries and gets the venv (scripts/python-env.sh), then sets `build`
# (absolute), `python` (the venv's interpreter) and `suite_args` (the rest, for pytest). Exits 2
# when the build is missing, 77 (ctest's SKIP_RETURN_CODE) when PyPI cannot be reached for the
# venv (python-env.sh exit 75, the machine's limit), 1 when the venv fails otherwise (our package
# does not build: a failure, never a skip).
python_suite_setup() {
  local label=$1 tool env_status=0 env_out repo given
  shift
  repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  given="$repo/build"
  if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then
    given="$1"
    shift
  fi
  suite_args=("$@")
  build="$(cd "$given" 2>/dev/null && pwd)" || { echo "$label: no build folder '$given'" >&2; exit 2; }
  for tool in canfleet canfleet-node; do
    if [ ! -x "$build/bin/$tool" ]; then
      echo "$label: $build/bin/$tool is missing (build the project first)" >&2
      exit 2
    fi
  done
  env_out="$("$repo/scripts/python-env.sh" 2>&1)" || env_status=$?
  if [ "$env_status" -ne 0 ]; then
    echo "$label: scripts/python-env.sh could not provide the venv (exit $env_status):" >&2
    echo "$env_out" >&2
    [ "$env_status" -eq 75 ] && exit 77
    exit 1
  fi
  python="$(printf '%s\n' "$env_out" | tail -n 1)"
  export PYTHONDONTWRITEBYTECODE=1  # no __pycache__ in the source tree
}

# python_suite_pytest NAME DOMAIN [PYTEST_ARGS...]: runs pytest on the current folder against the
# build's binaries (CANFLEET_BIN_DIR), on DDS domain DOMAIN unless CANFLEET_DDS_DOMAIN is set (each
# suite has its own, so suites running side by side do not see each other's fleets), with the
# suite's arguments; JUnit to BUILD/NAME-junit.xml. Replaces the shell.
python_suite_pytest() {
  local name=$1 domain=$2
  shift 2
  export CANFLEET_BIN_DIR="$build/bin"
  export CANFLEET_DDS_DOMAIN="${CANFLEET_DDS_DOMAIN:-$domain}"
  exec "$python" -m pytest -p no:cacheprovider -rs "$@" "--junitxml=$build/$name-junit.xml" "${suite_args[@]}" .
}
