#!/usr/bin/env bash
# Regenerates the outputs shown in README.md, topologies/README.md and tools/canfleet/README.md from
# the code: runs every command example (tests/docs/doc_examples.py --update) against the fleets they
# describe and writes what they printed into the files. Review the change with `git diff` before
# committing it. ctest's readme_examples checks the files against the code in every test run.
#   scripts/readme-captures.sh [BUILD_DIR]     default build (built by scripts/test.sh build)
set -euo pipefail
cd "$(dirname "$0")/.."
exec python3 tests/docs/doc_examples.py --build-dir "${1:-build}" --update \
  README.md topologies/README.md tools/canfleet/README.md
