#!/bin/sh
# SPDX-License-Identifier: MIT
# The host tools read a capture through the streaming reader (host_tools/capture/capture.h
# read_capture): a FIFO or stdin ("-") gives exactly what the file gives, and memory does
# not grow with the capture's size.
#   tools_stream.sh TOOL BINDIR SRCDIR WORKDIR
#   TOOL = view | calib | calib-memory | eval | eval-memory | serve-memory
set -eu
tool=$1 B=$2 S=$3 d=$4
rm -rf "$d"; mkdir -p "$d"; cd "$d"
"$B/sim/sl-sim" "$S/scenes/demo_three_poles.ini" --rotations 20 -o s.colossus --gt s.gt.csv --quiet
fifo() { rm -f f.fifo; mkfifo f.fifo; cat "$1" > f.fifo & }
# The tools name their input in their report, and a calibration file its date of writing:
# compare everything else.
strip() { sed -e '/^date = /d' -e 's#s\.colossus#INPUT#g; s#f\.fifo#INPUT#g; s#s\.pcapng#INPUT#g' -e 's#\([ (]\)-\([ ):]\)#\1INPUT\2#g' \
              -e 's#; *-$#;   INPUT#' -e 's#[a-z]*\.\(png\|ini\)#OUT#g' "$1"; }
same() { strip "$1" > "$1.s"; strip "$2" > "$2.s"; diff "$1.s" "$2.s"; }
case $tool in
view)
  "$B/view/sl-view" s.colossus --board paper-sim --title T --out file.png > file.txt
  grep -q '3 detections' file.txt
  fifo s.colossus; "$B/view/sl-view" f.fifo --board paper-sim --title T --out fifo.png > fifo.txt
  cat s.colossus | "$B/view/sl-view" - --board paper-sim --title T --out pipe.png > pipe.txt
  cmp file.png fifo.png; cmp file.png pipe.png; same file.txt fifo.txt; same file.txt pipe.txt ;;
calib)
  "$B/calib/sl-calib" shadow s.colossus --board paper-sim --out-ini file.ini > file.txt
  cat s.colossus | "$B/calib/sl-calib" shadow - --board paper-sim --out-ini pipe.ini > pipe.txt
  fifo s.colossus; "$B/calib/sl-calib" shadow f.fifo --board paper-sim --out-ini fifo.ini > fifo.txt
  grep -q '20 rotations' file.txt
  same file.ini pipe.ini; same file.txt pipe.txt; same file.ini fifo.ini; same file.txt fifo.txt ;;
eval)
  # bbox extraction from a file, stdin and a FIFO; the pipeline from a FIFO and from the
  # pcapng of the same stream (reassembled now, where the whole file used to be fed raw).
  "$B/eval/sl-eval" run s.colossus s.gt.csv --board paper-sim > file.txt
  cat s.colossus | "$B/eval/sl-eval" run - s.gt.csv --board paper-sim > pipe.txt
  grep -q '20 rotations' file.txt; same file.txt pipe.txt
  sc="--extract pipeline --scene $S/scenes/demo_three_poles.ini"
  "$B/eval/sl-eval" run s.colossus s.gt.csv $sc > pfile.txt
  fifo s.colossus; "$B/eval/sl-eval" run f.fifo s.gt.csv $sc > pfifo.txt
  "$B/replay/sl-replay" to-pcapng s.colossus --out s.pcapng
  "$B/eval/sl-eval" run s.pcapng s.gt.csv $sc > ppcap.txt
  grep -q 'detected' pfile.txt; same pfile.txt pfifo.txt; same pfile.txt ppcap.txt
  ! "$B/eval/sl-eval" run missing.colossus s.gt.csv 2> err.txt
  grep -q 'missing.colossus' err.txt ;;
calib-memory)
  # sl-calib shadow on 4 vs 15 copies of the capture (80 / 300 rotations, 17 / 66 MB)
  # through a pipe: peak RSS grows <= 16 MiB (it used to keep every rotation, ~200 KB
  # each), and the calibration equals the one from the file.
  for k in 4 15; do
    i=0; while [ $i -lt $k ]; do cat s.colossus; i=$((i + 1)); done > big$k
    # Under AddressSanitizer freed frames wait in a 256 MiB quarantine (as for serve below).
    cat big$k | ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}quarantine_size_mb=4" \
      /usr/bin/time -v -o time$k.txt "$B/calib/sl-calib" shadow - --board paper-sim --out-ini pipe.ini > pipe$k.txt
    grep -q "$((k * 20)) rotations" pipe$k.txt
  done
  "$B/calib/sl-calib" shadow big15 --board paper-sim --out-ini file.ini > file15.txt
  sed -i "s#big15#INPUT#g" file15.txt file.ini
  same file.ini pipe.ini; same file15.txt pipe15.txt
  a=$(sed -n 's/.*Maximum resident set size (kbytes): //p' time4.txt)
  b=$(sed -n 's/.*Maximum resident set size (kbytes): //p' time15.txt)
  echo "sl-calib shadow peak RSS: $a KiB for 80 rotations, $b KiB for 300 rotations"
  test $((b - a)) -le 16384 ;;
eval-memory)
  # 4 vs 15 copies of the capture (17 / 66 MB) through a pipe: peak RSS grows < 8 MiB.
  for k in 4 15; do
    i=0; while [ $i -lt $k ]; do cat s.colossus; i=$((i + 1)); done > big$k
    cat big$k | /usr/bin/time -v -o time$k.txt "$B/eval/sl-eval" run - s.gt.csv --board paper-sim > out$k.txt
    grep -q "$((k * 20)) rotations" out$k.txt
  done
  a=$(sed -n 's/.*Maximum resident set size (kbytes): //p' time4.txt)
  b=$(sed -n 's/.*Maximum resident set size (kbytes): //p' time15.txt)
  echo "sl-eval run peak RSS: $a KiB for 17 MB, $b KiB for 66 MB"
  test $((b - a)) -le 8192 ;;
serve-memory)
  # sl-replay serve of 4 vs 15 copies (17 / 66 MB) to a recording client (--rate max, the
  # client records for 8 s, the server stops after 10 s): the server's peak RSS grows
  # < 8 MiB (it used to load the whole capture). However much of it the client gets on a
  # loaded machine, the bound must hold; the client must get something.
  for k in 4 15; do
    i=0; while [ $i -lt $k ]; do cat s.colossus; i=$((i + 1)); done > big$k
    # Under AddressSanitizer freed blocks wait in a quarantine (256 MiB by default) before
    # reuse, which would grow with the messages served: keep it small for this measurement.
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}quarantine_size_mb=4" \
    /usr/bin/time -v -o time$k.txt "$B/replay/sl-replay" serve big$k --port 0 --rate max --timeout 10 \
      > serve$k.txt 2> serve$k.err &
    pid=$!; port=""; n=0
    while [ -z "$port" ] && [ $n -lt 600 ] && kill -0 $pid 2>/dev/null; do
      # only a whole line (its newline written): never a port number cut short
      if [ "$(tail -c 1 serve$k.txt 2>/dev/null | od -An -tx1 | tr -d ' ')" = 0a ]; then
        port=$(sed -n 's/^sl-replay: listening on 127\.0\.0\.1:\([0-9][0-9]*\)$/\1/p' serve$k.txt)
      fi
      n=$((n + 1)); sleep 0.05
    done
    rrc=0
    if [ -n "$port" ]; then
      "$B/replay/sl-replay" record --radar 127.0.0.1:$port --out rec$k.colossus --duration 8 > rec$k.txt 2>&1 || rrc=$?
    fi
    src=0; wait $pid || src=$?
    if [ -z "$port" ] || [ $src -ne 0 ] || [ ! -s rec$k.colossus ]; then
      echo "FAIL: $k copies: port '$port', serve exit $src, record exit $rrc"
      cat serve$k.txt serve$k.err rec$k.txt 2>/dev/null; exit 1
    fi
  done
  a=$(sed -n 's/.*Maximum resident set size (kbytes): //p' time4.txt)
  b=$(sed -n 's/.*Maximum resident set size (kbytes): //p' time15.txt)
  echo "sl-replay serve peak RSS: $a KiB for 17 MB ($(wc -c < rec4.colossus) bytes served), $b KiB for 66 MB ($(wc -c < rec15.colossus) bytes served)"
  test $((b - a)) -le 8192 ;;
*) echo "tools_stream.sh: unknown tool $tool" >&2; exit 2 ;;
esac
echo "ok: $tool"
