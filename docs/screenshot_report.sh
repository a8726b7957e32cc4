#!/usr/bin/env bash
# A screenshot of the report's home page as a reader sees it on opening (the report opens at the scoreboard),
# taken with headless Chromium: no window, no network, a throw-away browser profile.
#
#   docs/screenshot_report.sh [REPORT.html] [OUT.png] [WIDTH,HEIGHT]
#   docs/screenshot_report.sh                                           # results/report.html -> report_screenshot.png
#   docs/screenshot_report.sh results/paper/report.html paper.png 1400,2000
#
# Needs Chromium: `apt-get install -y chromium` (Debian/Ubuntu), or set CHROMIUM=/path/to/chrome.
# The report is a JavaScript page: --virtual-time-budget lets it build its page before the picture is taken.
set -euo pipefail
report=${1:-results/report.html}
out=${2:-report_screenshot.png}
size=${3:-1400,1000}
browser=${CHROMIUM:-$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)}
if [ -z "$browser" ]; then
    echo "no Chromium found: apt-get install -y chromium, or set CHROMIUM=/path/to/browser" >&2
    exit 1
fi
if [ ! -f "$report" ]; then
    echo "$report: no such report; make it with python3 run.py (or snakemake --report $report)" >&2
    exit 1
fi
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
"$browser" --headless --no-sandbox --disable-gpu --disable-background-networking --disable-component-update \
    --disable-sync --no-first-run --hide-scrollbars --user-data-dir="$profile" --virtual-time-budget=20000 \
    --window-size="$size" --screenshot="$(realpath -m "$out")" "file://$(realpath "$report")" 2>/dev/null
echo "$out"
