#!/usr/bin/env bash
# A headless browser for the report test (tests/test_verify.py opens report.html in it): Debian's chromium.
# Idempotent; says how to install it by hand when it cannot.
set -u
for b in chromium chromium-browser google-chrome; do
    if command -v "$b" >/dev/null 2>&1; then echo "browser: $b ok"; exit 0; fi
done
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq -o DPkg::Lock::Timeout=600 >/dev/null \
        && apt-get install -y -qq -o DPkg::Lock::Timeout=600 chromium >/dev/null \
        && { echo "browser: chromium installed"; exit 0; }
fi
echo "browser: chromium missing: install it as root ('sudo apt-get install chromium')"
exit 1
