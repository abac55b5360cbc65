#!/bin/sh
# SPDX-License-Identifier: MIT
# sl-calib elongation streams each capture (calib_elong.h ElongStream): memory does not grow
# with the capture's length, and a pipe gives what the file gives.
#   elong_stream.sh BINDIR SRCDIR WORKDIR
set -eu
B=$1 S=$2 d=$3
rm -rf "$d"; mkdir -p "$d"; cd "$d"
"$B/sim/sl-sim" "$S/scenes/demo_three_poles.ini" --rotations 20 -o s.colossus --gt s.gt.csv --quiet
C="$B/calib/sl-calib"
rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1"; }
# The report and the files name the capture, and the calibration block its date: compare
# everything else.
strip() { sed -e '/^; sl-calib [0-9]/d' -e 's#^\(s\.colossus\|big15\|-\),#INPUT,#; s#^INPUT,\(big15\|-\),#INPUT,INPUT,#' \
              -e 's#\(file\|pipe\)[0-9]*\.\(ini\|csv\|png\)#OUT#g' "$1"; }
same() { strip "$1" > "$1.s"; strip "$2" > "$2.s"; diff "$1.s" "$2.s"; }
# sl-sim truth (one position per pole over the 20 rotations): the pipe equals the file.
"$C" elongation s.colossus --truth s.gt.csv --board paper-sim --out-ini file.ini --csv file.csv > file.txt
cat s.colossus | "$C" elongation - --truth s.gt.csv --board paper-sim --out-ini pipe.ini --csv pipe.csv > pipe.txt
grep -q '3 positions from 1 captures' file.txt
same file.txt pipe.txt; same file.ini pipe.ini; same file.csv pipe.csv
# One position over the whole capture (a list file: the pole at 3.0 m), 4 vs 15 copies of
# the capture (80 / 300 rotations, 17 / 66 MB) through a pipe: peak RSS grows <= 8 MiB (the
# command kept every rotation, ~210 KB each: +45 MiB), and the result equals the file's.
printf 'capture,range_m\n-,3.0\nbig15,3.0\n' > list.csv
for k in 4 15; do
  i=0; while [ $i -lt $k ]; do cat s.colossus; i=$((i + 1)); done > big$k
  # Under AddressSanitizer freed frames wait in a 256 MiB quarantine: keep it small.
  cat big$k | ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}quarantine_size_mb=4" \
    /usr/bin/time -v -o time$k.txt "$C" elongation - --truth list.csv --board paper-sim \
    --out-ini pipe$k.ini --csv pipe$k.csv > pipe$k.txt
  grep -q "^-,-,0,-1,$((k * 20)),16,1," pipe$k.csv # found, over every rotation
done
"$C" elongation big15 --truth list.csv --board paper-sim --out-ini file15.ini --csv file15.csv > file15.txt
same file15.txt pipe15.txt; same file15.ini pipe15.ini; same file15.csv pipe15.csv
a=$(rss time4.txt) b=$(rss time15.txt)
echo "sl-calib elongation peak RSS: $a KiB for 80 rotations, $b KiB for 300 rotations"
test $((b - a)) -le 8192
echo "ok"
