#!/usr/bin/env bash
# Structure check: fails when a library source file (libs/, *.cpp and *.h) exceeds 600 lines or a
# function in one exceeds 120 lines (functions as universal-ctags sees them, from the line of
# their name to their closing brace; a lambda counts in the function that holds it).
#
# Today's offenders are listed, with their current sizes, in scripts/structure-allowlist.txt: a
# listed offender may shrink but not grow, a new offender fails, and a listed one that now passes
# (or is smaller than listed) is printed so that the list only shrinks.
#
#   bash scripts/check-structure.sh                  check the tree
#   bash scripts/check-structure.sh --with-self-test first check the checker on temporary trees
#   bash scripts/check-structure.sh --root DIR --allowlist FILE   check another tree
#
# Needs universal-ctags (installed when missing). Exit code 0: passes; 1: fails.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/.." && pwd)
allowlist=""
self_test=0
max_file_lines=600
max_function_lines=120

while [ $# -gt 0 ]; do
  case "$1" in
    --root) root=$(cd "$2" && pwd); shift 2 ;;
    --allowlist) allowlist=$2; shift 2 ;;
    --with-self-test) self_test=1; shift ;;
    -h|--help) sed -n '2,14p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "check-structure.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$allowlist" ] || allowlist="$root/scripts/structure-allowlist.txt"

if ! command -v ctags-universal >/dev/null 2>&1; then
  source "$here/install-packages.sh"
  install_missing_packages "${multibin_check_packages[@]}"
fi

# measure ROOT: prints one line per file and per function over its limit:
#   LINES file PATH
#   LINES function PATH QUALIFIED_NAME
measure() {
  local tree=$1
  (
    cd "$tree"
    [ -d libs ] || exit 0
    find libs -type f \( -name '*.cpp' -o -name '*.h' \) -print0 | sort -z |
      xargs -0 -r wc -l | awk -v max="$max_file_lines" '$2 != "total" && $1 > max { print $1, "file", $2 }'
    # end|line|path|scope|name|scopeKind; lambdas inside a function count in that function;
    # anonymous namespaces get a stable name.
    find libs -type f \( -name '*.cpp' -o -name '*.h' \) -print0 | sort -z |
      xargs -0 -r ctags-universal --languages=C++ --map-C++=+.h --kinds-C++=f --fields=+neZ \
        -x --_xformat='%{end}|%n|%F|%{scope}|%N|%{scopeKind}' |
      awk -F'|' -v max="$max_function_lines" '
        $5 ~ /^__anon/ && $6 == "function" { next }
        $1 !~ /^[0-9]+$/ { next }
        {
          scope = $4; name = $5
          gsub(/__anon[0-9a-f]+/, "{anon}", scope); gsub(/__anon[0-9a-f]+/, "{lambda}", name)
          if (scope == "" || scope == "-") q = name; else q = scope "::" name
          len = $1 - $2 + 1
          if (len > max) print len, "function", $3, q
        }'
  ) | sort -k3,3 -k4 -k1,1n |
    # an overloaded name appears once, with its longest definition
    awk '{ key = $0; sub(/^[0-9]+ /, "", key); size[key] = $1 }
         END { for (k in size) print size[k], k }' | sort -k3,3 -k2,2 -k4
}

# check ROOT ALLOWLIST: compares the tree's offenders with the allow-list; returns 1 on failure.
check() {
  local tree=$1 list=$2
  local measured
  measured=$(measure "$tree")
  [ -f "$list" ] || list=/dev/null
  awk -v maxf="$max_file_lines" -v maxg="$max_function_lines" '
    FILENAME == ARGV[1] {                        # the allow-list
      sub(/#.*/, ""); if ($0 ~ /^[ \t]*$/) next
      key = $0; sub(/^[ \t]*[0-9]+[ \t]+/, "", key); gsub(/[ \t]+/, " ", key); sub(/ $/, "", key)
      listed[key] = $1; order[++n] = key; next
    }
    {                                            # the measured offenders
      key = $0; sub(/^[0-9]+ /, "", key); now[key] = $1
    }
    END {
      bad = 0
      for (k in now) {
        limit = (k ~ /^file /) ? maxf : maxg
        if (!(k in listed)) {
          printf "FAIL new offender (limit %d): %d %s\n", limit, now[k], k; bad = 1
        } else if (now[k] > listed[k]) {
          printf "FAIL grew past its allow-list size %d: %d %s\n", listed[k], now[k], k; bad = 1
        }
      }
      for (i = 1; i <= n; i++) {
        k = order[i]
        if (!(k in now))
          printf "now passes, remove it from the allow-list: %s (listed %d)\n", k, listed[k]
        else if (now[k] < listed[k])
          printf "shrank, lower its allow-list size: %d %s (listed %d)\n", now[k], k, listed[k]
        else
          printf "allowed: %d %s\n", now[k], k
      }
      exit bad
    }' "$list" <(printf '%s\n' "$measured" | sed '/^$/d')
}

run_self_test() {
  local tmp status
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' RETURN
  mkdir -p "$tmp/libs/a"
  # a short function, a 125-line function, a file of 610 lines
  {
    echo 'int shortOne(int x) {'; echo '  return x;'; echo '}'
  } >"$tmp/libs/a/ok.cpp"
  {
    echo 'namespace ns {'
    echo 'int tooLong(int x) {'
    for i in $(seq 1 123); do echo "  x += $i;"; done
    echo '}'
    echo '}'
  } >"$tmp/libs/a/long_function.cpp"
  : >"$tmp/empty.txt"
  fail() { echo "check-structure self-test FAILED: $*" >&2; exit 1; }

  check "$tmp" "$tmp/empty.txt" >"$tmp/out" && fail "a 125-line function passed"
  grep -q 'FAIL new offender (limit 120): 125 function libs/a/long_function.cpp ns::tooLong' \
    "$tmp/out" || fail "the long function was not named: $(cat "$tmp/out")"

  printf '# comment\n125 function libs/a/long_function.cpp ns::tooLong\n' >"$tmp/list.txt"
  check "$tmp" "$tmp/list.txt" >"$tmp/out" || fail "a listed offender at its size failed"

  printf '124 function libs/a/long_function.cpp ns::tooLong\n' >"$tmp/list.txt"
  check "$tmp" "$tmp/list.txt" >"$tmp/out" && fail "an offender that grew passed"

  for i in $(seq 1 610); do echo "// $i"; done >"$tmp/libs/a/long_file.h"
  check "$tmp" "$tmp/empty.txt" >"$tmp/out" && fail "a 610-line file passed"
  grep -q 'FAIL new offender (limit 600): 610 file libs/a/long_file.h' "$tmp/out" ||
    fail "the long file was not named: $(cat "$tmp/out")"
  rm "$tmp/libs/a/long_file.h" "$tmp/libs/a/long_function.cpp"

  printf '125 function libs/a/long_function.cpp ns::tooLong\n' >"$tmp/list.txt"
  check "$tmp" "$tmp/list.txt" >"$tmp/out" || fail "a clean tree failed"
  grep -q 'now passes, remove it from the allow-list: function libs/a/long_function.cpp ns::tooLong' \
    "$tmp/out" || fail "a listed entry that now passes was not reported"
  echo "check-structure self-test passed"
}

if [ "$self_test" = 1 ]; then
  (run_self_test)
fi
if check "$root" "$allowlist"; then
  echo "check-structure: passed (files <= $max_file_lines lines, functions <= $max_function_lines lines, allow-list $allowlist)"
else
  echo "check-structure: FAILED (files <= $max_file_lines lines, functions <= $max_function_lines lines, allow-list $allowlist)" >&2
  exit 1
fi
