#!/bin/sh
# Loads an HTML page in headless Chromium in a 1,400-pixel window and prints, for each table,
# "fits" or "scrolls by N px" (its content wider than its box): a table that scrolls hides its
# right-hand columns from a screenshot.
# Usage: tables_fit.sh CHROMIUM PAGE.html PROFILE_DIR
chromium=$1 page=$2 profile=$3
rm -rf "$profile"
measured="${page%.html}.measured.html"
sed 's|</body>|<script>window.addEventListener("load", () => { const out = document.createElement("pre"); out.id = "tables-fit"; out.textContent = [...document.querySelectorAll("table")].map(t => t.scrollWidth > t.clientWidth ? "scrolls by " + (t.scrollWidth - t.clientWidth) + " px" : "fits").join(" "); document.body.append(out); });</script></body>|' \
    "$page" > "$measured"
"$chromium" --headless --no-sandbox --disable-gpu --user-data-dir="$profile" --window-size=1400,1000 \
    --virtual-time-budget=10000 --dump-dom "file://$measured" 2>/dev/null |
    grep -o 'id="tables-fit">[^<]*'
