#!/usr/bin/env bash
# A full disk. The work folder of a dataset run sits on a small tmpfs; each
# stage in turn is rerun (its stamp removed) with the disk filled so that it
# runs out of space partway through its outputs (and, for train and vote,
# again with the disk full before they start). Each time the stage fails
# with exit 1 and a line that names the file it could not write and says
# the disk is full, leaves no temporary file or staging folder behind, and
# leaves its previous
# outputs as they were (the training stages excepted: make clears their
# outputs before they run, and they write resumable checkpoints). Once the
# space is freed, make finishes the stage, and the work folder is then
# byte-identical to a run that never ran out. The stages after it are not
# run again each time (their inputs are then the complete run's, byte for
# byte, and each stage's start-up is most of this test's time); a plain make
# at the end finishes the run.
# Mounting needs root; where it is not allowed the test is skipped (exit
# 77; in CI it fails: test_lib.sh's skip).
# Usage: disk_full.sh BIN_DIR
source "$(dirname "${BASH_SOURCE[0]}")/../pipeline/test_lib.sh" "$1"
disk="$tmp/disk"
mkdir -p "$disk"
mount -t tmpfs -o size=32m tmpfs "$disk" 2> /dev/null || skip "cannot mount a tmpfs here (needs root)"
trap 'umount -l "$disk" 2> /dev/null; rm -rf "$tmp"' EXIT

tiny_lerf_run "$disk/work"
w="$disk/work/demo"
outputs() { work_outputs "$disk/work"; }
# Fills the disk but for $1 bytes.
leave_free() {
  rm -f "$disk/filler"
  local free
  free=$(df --output=avail -B1 "$disk" | tail -1)
  if ((free > $1)); then fallocate -l $((free - $1)) "$disk/filler"; fi
}
# Bytes a stage's outputs take on the disk.
outputs_size() {
  case "$1" in
    sfm) du -s -B1 "$w/sfm" ;;
    train) du -s -B1 -c "$w/checkpoints" "$w/point_cloud" "$w/test" | tail -1 ;;
    *) du -s -B1 "$w/$1" ;;
  esac | cut -f1
}

mk "${run[@]}" > "$tmp/reference.log" 2>&1 || { tail -5 "$tmp/reference.log"; fail "the reference run failed"; }
reference=$(outputs)

for stage in sfm train vote learn render embed query eval report; do
  # A disk already full: once for a training stage, once for a folder stage.
  fills=(half)
  [[ "$stage" != train && "$stage" != vote ]] || fills+=(0)
  for left in "${fills[@]}"; do
    [ "$left" = half ] && left=$(($(outputs_size "$stage") / 2))
    before=$(outputs)
    rm "$w/stamps/$stage.done"
    # The stages that clear their outputs first would free the space they
    # need: clear them before filling the disk (as make does for training; a
    # new SfM would redo every step).
    case "$stage" in
      sfm) rm -rf "$w/sfm" ;;
      train) (cd "$w" && rm -rf checkpoints point_cloud test train_log.jsonl training_curve.png) ;;
      learn) rm -rf "$w/learn" ;;
    esac
    leave_free "$left"
    what="$stage with $left bytes free"
    if mk "${run[@]}" "demo.$stage" > "$tmp/full.log" 2>&1; then
      fail "$what: the stage did not fail"
    fi
    grep -q "stage $stage failed (exit 1)" "$tmp/full.log" ||
      { cat "$tmp/full.log"; fail "$what: no exit 1"; }
    grep "No space left on device" "$tmp/full.log" | grep -q "$disk/work" ||
      { cat "$tmp/full.log"; fail "$what: no line names the file and the full disk"; }
    ! grep -E -q "terminate called|Segmentation|Aborted|core dumped" "$tmp/full.log" ||
      { cat "$tmp/full.log"; fail "$what: the stage crashed"; }
    left_over=$(find "$disk/work" -name '.*.tmp-*' -o -name '.staging-*')
    [ -z "$left_over" ] || fail "$what: left behind $left_over"
    case "$stage" in
      sfm | train | learn) ;;
      *) [ "$(outputs)" = "$before" ] || {
           diff <(echo "$before") <(outputs) | head -5 || true
           fail "$what: the previous outputs changed"; } ;;
    esac
    rm "$disk/filler"
    mk "${run[@]}" "demo.$stage" > "$tmp/after.log" 2>&1 ||
      { tail -5 "$tmp/after.log"; fail "$what: the stage failed again once space was freed"; }
    [ "$(outputs)" = "$reference" ] || {
      diff <(echo "$reference") <(outputs) | head -5 || true
      fail "$what: after freeing space, the outputs differ from the run that never ran out"; }
    case "$stage" in
      sfm | train | learn) kept="nothing half-written" ;;
      *) kept="previous outputs kept" ;;
    esac
    echo "$what: failed cleanly, $kept; finished once space was freed"
  done
done
mk "${run[@]}" > "$tmp/after.log" 2>&1 || { tail -5 "$tmp/after.log"; fail "the last plain make failed"; }
[ "$(outputs)" = "$reference" ] || fail "after the last plain make, the outputs differ from the first run's"
echo "PASS"
