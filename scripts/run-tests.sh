#!/usr/bin/env bash
# The test command of the README. Runs the whole suite; engine tests run for real.
# Under DEMCHECK_REQUIRE_ENGINES=1 (set by .ci/run) a missing engine fails instead of skipping.
set -u
venv=${1:-.venv}
"$venv/bin/python" -m pytest -q -p no:cacheprovider "${@:2}"
rc=$?
# pytest exits 5 when it collected nothing: that is a broken suite, not a pass.
if [ $rc -eq 5 ]; then echo "run-tests: no tests were collected"; exit 1; fi
exit $rc
