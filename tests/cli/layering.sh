#!/usr/bin/env bash
# The layers' dependency rules: includes across a forbidden layer and a
# learner in the runtime library's link closure, or an HTTP server in the
# loop's, fail (tests/cli/layering.py).
set -uo pipefail
animrt=$1
root=$2
build=$(dirname "$(dirname "$animrt")")
exec /usr/bin/python3 "$root/tests/cli/layering.py" "$root" "$build"
