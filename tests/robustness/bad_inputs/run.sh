#!/usr/bin/env bash
# Runs one bad-input table: every row is a tpsim command line that must fail cleanly.
#
#   run.sh TPSIM TABLE.tsv [BUILD_DIR] [ROW_NAME]
#
# Table format (tests/robustness/bad_inputs/<area>.tsv): one case per line, four fields
# separated by tabs; lines starting with '#' and blank lines are ignored.
#   name        a short unique name for the case (no spaces)
#   arguments   tpsim's arguments, split at spaces (an argument cannot hold a space). Words may
#               contain these placeholders:
#                 @files/NAME  tests/robustness/bad_inputs/files/NAME (committed inputs)
#                 @tmp/NAME    NAME in a scratch directory; make_inputs.sh writes the generated
#                              inputs there (huge, sparse or repetitive files) before the rows run
#                 @fifo        a FIFO with no writer, created in the scratch directory
#                 @repo/PATH   PATH in the source tree (scenes/cornell.toml, configs/tiny.toml)
#                 @build/PATH  PATH in the build tree (kernels/tracer.elf)
#   fragment    text that stderr's line must contain (matched literally)
#   exit        the exit status tpsim must give (2 for every bad input)
#
# Each row runs in the scratch directory under `timeout 20` and `ulimit -v` (2 GiB), stdin from
# /dev/null. A row passes when the exit status is the expected one and, for a non-zero status,
# stderr is exactly one line that starts with "tpsim: " and contains the fragment, and nothing
# on stdout or stderr looks like a crash (abort, uncaught exception, sanitizer report). For an
# expected status of 0 the fragment is looked for in stdout and stderr instead. Every failing
# row is printed with what tpsim gave; the script exits 1 if any row failed.
set -uo pipefail

if (($# < 2)); then
    echo "usage: $0 TPSIM TABLE.tsv [BUILD_DIR] [ROW_NAME]" >&2
    exit 2
fi
tpsim=$(realpath "$1")
table=$2
build=$(realpath "${3:-$(dirname "$tpsim")}")
only=${4:-}
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../../.." && pwd)

scratch=$(mktemp -d "${TMPDIR:-/tmp}/tpsim-bad-inputs.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
"$here/make_inputs.sh" "$scratch" || { echo "make_inputs.sh failed" >&2; exit 1; }
mkfifo "$scratch/fifo"

crash_pattern='terminate called|Assertion .* failed|Aborted|Segmentation fault|core dumped'
crash_pattern+='|AddressSanitizer|UndefinedBehaviorSanitizer|runtime error:|std::bad_alloc'

rows=0 failures=0
while IFS= read -r line || [[ -n $line ]]; do
    [[ -z $line || $line == \#* ]] && continue
    # Split at every tab (read would merge the tabs around an empty field).
    readarray -td $'\t' fields < <(printf '%s' "$line")
    name=${fields[0]} arguments=${fields[1]:-} fragment=${fields[2]:-} expected=${fields[3]:-}
    [[ -n $only && $name != "$only" ]] && continue
    rows=$((rows + 1))
    if ((${#fields[@]} != 4)) || [[ -z $fragment || ! $expected =~ ^[0-9]+$ ]]; then
        echo "FAIL $name: malformed row (want 4 tab-separated fields: name, arguments," \
            "fragment, exit status)"
        failures=$((failures + 1))
        continue
    fi
    argv=()
    for word in $arguments; do
        word=${word//@files\//$here/files/}
        word=${word//@tmp\//$scratch/}
        word=${word//@fifo/$scratch/fifo}
        word=${word//@repo\//$repo/}
        word=${word//@build\//$build/}
        argv+=("$word")
    done
    started=$SECONDS
    (
        ulimit -v 2097152
        cd "$scratch" && exec timeout -k 5 20 "$tpsim" "${argv[@]}" </dev/null \
            >"$scratch/.stdout" 2>"$scratch/.stderr"
    )
    status=$?
    ((SECONDS - started > 5)) && echo "note $name: took $((SECONDS - started)) s"
    stdout=$(cat "$scratch/.stdout")
    stderr=$(cat "$scratch/.stderr")
    lines=$(wc -l <"$scratch/.stderr")
    problem=""
    if ((status == 124)); then
        problem="timed out after 20 s"
    elif ((status != expected)); then
        problem="exit status $status, expected $expected"
    elif grep -Eq "$crash_pattern" "$scratch/.stdout" "$scratch/.stderr"; then
        problem="output looks like a crash"
    elif ((expected == 0)); then
        [[ "$stdout$stderr" == *"$fragment"* ]] || problem="output lacks '$fragment'"
    elif [[ $lines -ne 1 || $stderr != "tpsim: "* ]]; then
        problem="stderr is not one 'tpsim: ' line ($lines lines)"
    elif [[ $stderr != *"$fragment"* ]]; then
        problem="stderr lacks '$fragment'"
    fi
    if [[ -n $problem ]]; then
        failures=$((failures + 1))
        echo "FAIL $name: $problem"
        echo "  command: tpsim ${argv[*]}"
        echo "  stderr: $(head -c 2000 <<<"$stderr" | sed '2,$s/^/          /')"
        [[ -n $stdout ]] && echo "  stdout: $(head -c 1000 <<<"$stdout" | sed '2,$s/^/          /')"
    fi
    rm -f "$scratch"/.stdout "$scratch"/.stderr
done <"$table"

echo "$(basename "$table"): $((rows - failures)) of $rows rows pass"
((rows > 0 && failures == 0))
