#!/bin/sh
# SPDX-License-Identifier: MIT
# sl-view streams a capture (host_tools/view/main.cpp, class Viewer): memory does not grow
# with the capture's length, a pipe gives the pictures and text the file gives, --all from
# a pipe draws every rotation, and --motion (which reads the capture twice) is a usage
# error on stdin or a FIFO.
#   view_stream.sh CASE BINDIR SRCDIR WORKDIR
#   CASE = memory | motion-stream | all-pipe
set -eu
case=$1 B=$2 S=$3 d=$4
rm -rf "$d"; mkdir -p "$d"; cd "$d"
"$B/sim/sl-sim" "$S/scenes/demo_three_poles.ini" --rotations 20 -o s.colossus --quiet
V="$B/view/sl-view"
rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1"; }
case $case in
memory)
  # 4 vs 15 copies of the capture (80 / 300 rotations, 17 / 66 MB) through a pipe, for the
  # last rotation (a ring of one) and for rotation 5: peak RSS grows <= 8 MiB (sl-view kept
  # every rotation, ~210 KB each: +45 MiB), and the picture and text equal the file's.
  for k in 4 15; do
    i=0; while [ $i -lt $k ]; do cat s.colossus; i=$((i + 1)); done > big$k
  done
  for r in -1 5; do
    for k in 4 15; do
      # Under AddressSanitizer freed frames wait in a 256 MiB quarantine: keep it small.
      cat big$k | ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}quarantine_size_mb=4" \
        /usr/bin/time -v -o time$k$r.txt "$V" - --board paper-sim --title T --rotation $r \
        --out pipe$k$r.png > pipe$k$r.txt
      grep -q "of $((k * 20)) = --rotation" pipe$k$r.txt
    done
    "$V" big15 --board paper-sim --title T --rotation $r --out file15$r.png > file15$r.txt
    cmp pipe15$r.png file15$r.png
    sed 's#pipe15-*[0-9]*\.png#OUT#' pipe15$r.txt > p.txt; sed 's#file15-*[0-9]*\.png#OUT#' file15$r.txt > f.txt
    diff p.txt f.txt
    a=$(rss time4$r.txt) b=$(rss time15$r.txt)
    echo "sl-view --rotation $r peak RSS: $a KiB for 80 rotations, $b KiB for 300 rotations"
    test $((b - a)) -le 8192
  done ;;
motion-stream)
  # --motion reads the capture twice (the pipeline, then the pictures): stdin and a FIFO are
  # usage errors naming the option; the file works.
  rc=0; cat s.colossus | "$V" - --board paper-sim --motion 1 --out m.png > m.txt 2> m.err || rc=$?
  test $rc -eq 2; grep -q -- '--motion' m.err; test ! -e m.png
  rm -f f.fifo; mkfifo f.fifo
  rc=0; "$V" f.fifo --board paper-sim --motion 1 --out m.png > m.txt 2> m.err || rc=$?
  test $rc -eq 2; grep -q -- '--motion' m.err; test ! -e m.png
  "$V" s.colossus --board paper-sim --motion 1 --rotation 5 --out m.png > m.txt
  grep -q 'rotation 6 of 20' m.txt; test -s m.png ;;
all-pipe)
  # --all from a pipe draws each rotation as it comes (its pictures say "rotation K", the
  # count is not known while drawing): as many PNGs as from the file, same size.
  "$V" s.colossus --board paper-sim --all -q --out f.png > f.txt
  cat s.colossus | "$V" - --board paper-sim --all -q --out p.png > p.txt
  grep -q 'wrote 20 PNGs' f.txt; grep -q 'wrote 20 PNGs' p.txt
  test "$(ls p_*.png | wc -l)" -eq 20
  for i in 0000 0019; do test "$(head -c 24 p_$i.png | od -An -tx1)" = "$(head -c 24 f_$i.png | od -An -tx1)"; done ;;
*) echo "view_stream.sh: unknown case $case" >&2; exit 2 ;;
esac
echo "ok: $case"
