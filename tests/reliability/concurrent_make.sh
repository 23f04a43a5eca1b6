#!/usr/bin/env bash
# Two makes on the same work folder at once: the second refuses at once,
# naming the first, and touches nothing; the first finishes, and a third
# make finds everything up to date (nothing was corrupted). A make that was
# killed holds nothing: the next one runs.
# Usage: concurrent_make.sh BIN_DIR
source "$(dirname "${BASH_SOURCE[0]}")/../pipeline/test_lib.sh" "$1"
"$bin/op2gs-synth" "$tmp/data/demo" --views 10 --width 96 --height 72 --supersample 1 --points 800 \
  > /dev/null 2>&1 || fail "op2gs-synth"
run=(DATASET=photos DATA_ROOT="$tmp/data" WORK_ROOT="$tmp/run" ITERATIONS=150 STAGE_ONE=100
     TRAIN_OPTS="--densify-until 0")

mk "${run[@]}" sfm > "$tmp/sfm.log" 2>&1 || { tail -5 "$tmp/sfm.log"; fail "the scene did not build"; }
mk "${run[@]}" vote > "$tmp/first.log" 2>&1 &
first=$!
for _ in $(seq 50); do [ -s "$tmp/run/demo/logs/train.log" ] && break; sleep 0.1; done
[ -s "$tmp/run/demo/logs/train.log" ] || fail "the first make did not start training"
before=$(ls -l --time-style=+%s.%N "$tmp/run/demo/logs")
if mk "${run[@]}" vote > "$tmp/second.log" 2>&1; then fail "a second make ran beside the first"; fi
grep -q "another make (process [0-9]*) is running in this work folder" "$tmp/second.log" ||
  { cat "$tmp/second.log"; fail "the second make did not say why it refused"; }
[ "$(ls -l --time-style=+%s.%N "$tmp/run/demo/logs")" = "$before" ] || fail "the second make touched the logs"
wait "$first" || { tail -5 "$tmp/first.log"; fail "the first make failed"; }
mk "${run[@]}" -q vote || fail "after both, make -q says something is stale"

# A make killed outright leaves its process ID behind; the next make runs.
mk "${run[@]}" LEARN_OPTS="--lambda-o 0.2" learn > "$tmp/killed.log" 2>&1 &
killed=$!
for _ in $(seq 50); do [ -s "$tmp/run/demo/logs/learn.log" ] && break; sleep 0.1; done
read -r holder _ < "$tmp/run/.op2gs.make"  # its process ID and start time
kill -9 "$holder" || fail "no make process $holder to kill"
pkill -9 -f "op2gs-learn $tmp/run" || true
wait "$killed" 2>/dev/null || true
! kill -0 "$holder" 2>/dev/null || fail "the killed make lives on"
mk "${run[@]}" LEARN_OPTS="--lambda-o 0.2" learn > "$tmp/after.log" 2>&1 ||
  { tail -5 "$tmp/after.log"; fail "the make after a killed one did not run"; }
echo "PASS"
