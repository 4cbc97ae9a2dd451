#!/usr/bin/env bash
# scripts/peer-bench: without a Mantaflow source it says so and exits 0; a
# folder that is not a checkout is refused (exit 2, naming it). With
# MANTAFLOW_SRC set (`ctest -L peer`), the whole comparison runs and prints
# its table: Mantaflow's and morphoflow's steps and their ratio, per case.
set -u
root=$1
mode=$2
bin=$3
fail() { echo "FAIL: $*"; exit 1; }
if [ "$mode" = skip ]; then
  out=$(env -u MANTAFLOW_SRC "$root/scripts/peer-bench" 2>&1) || fail "no source: exit $?: $out"
  grep -q "skipped: no Mantaflow source given" <<< "$out" || fail "no source: $out"
  not=$(mktemp -d)
  out=$("$root/scripts/peer-bench" "$not" 2>&1)
  status=$?
  rm -rf "$not"
  [ $status -eq 2 ] || fail "not a checkout: exit $status: $out"
  grep -q "not a Mantaflow checkout" <<< "$out" || fail "not a checkout: $out"
  echo "peer-bench skips without a source and refuses a folder that is not one"
  exit 0
fi
[ -n "${MANTAFLOW_SRC:-}" ] || { echo "MANTAFLOW_SRC is not set: nothing to compare with"; exit 77; }
out=$(cd "$root" && MORPHOFLOW_BINARY=$bin PEER_BUILD=${PEER_BUILD:-$PWD/peer_build} scripts/peer-bench 2>&1) ||
  fail "peer-bench: $out"
echo "$out"
for c in "2D 512^2" "3D 128^3"; do
  grep -Eq "^\| $c \| [0-9.e+]+ \| [0-9.e+]+ \| [0-9.]+x \|$" <<< "$out" || fail "no row for $c"
done
