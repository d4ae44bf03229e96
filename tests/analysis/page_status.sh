#!/bin/sh
# Loads an HTML page in headless Chromium and prints the status its script records once every
# chart is drawn (report_page.js): data-status="ok|failed" and "charts drawn: N of M; errors: E".
# Usage: page_status.sh CHROMIUM PAGE.html PROFILE_DIR
chromium=$1 page=$2 profile=$3
rm -rf "$profile"
"$chromium" --headless --no-sandbox --disable-gpu --user-data-dir="$profile" \
    --virtual-time-budget=10000 --dump-dom "file://$page" 2>/dev/null |
    grep -o 'id="chart-status" data-status="[a-z]*">[^<]*'
