#!/bin/sh
# Runs every ```sh block of a course page, in order, as one script with `sh -e` in an empty
# folder that has the repository's scenes/, configs/ and course/ beside it (the pages' commands
# are written from the repository root) and tpsim on PATH. A block is left out when the line
# before its fence is `<!-- not run: REASON -->`: the pages' illustrative blocks say why.
#   run_doc_commands.sh PAGE.md TPSIM_BINARY_DIR SOURCE_DIR WORK_DIR
set -e
page=$1 bin=$2 source=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
# Blocks may be indented (in a list item); their lines lose the fence's indentation.
awk '
  match($0, /^ *```sh$/) { inside = skip ? 2 : 1; indent = RLENGTH - 5; next }
  /^ *```/ && inside { inside = 0; skip = 0; next }
  inside == 1 { print substr($0, indent + 1); next }
  inside == 2 { next }
  /^ *<!-- not run: .* -->$/ { skip = 1; next }
  NF { skip = 0 }
' "$page" > "$work/commands.sh"
if ! test -s "$work/commands.sh"; then
  grep -q '^ *```sh$' "$page" || { echo "$page has no \`\`\`sh block"; exit 1; }
  echo "SKIPPED: every \`\`\`sh block of $page is marked not run"
  exit 77
fi
# The pages start kernels with tpsim new-kernel (the course kit); a tpsim without it cannot
# run them, which is a skip, not a failure.
if grep -q 'tpsim new-kernel' "$work/commands.sh" && ! "$bin/tpsim" --help | grep -q new-kernel; then
  echo "SKIPPED: this tpsim has no new-kernel command"
  exit 77
fi
cd "$work"
ln -s "$source/scenes" scenes && ln -s "$source/configs" configs && ln -s "$source/course" course
PATH="$bin:$PATH" sh -ex commands.sh
echo "ALL COMMANDS RAN"
